// BVH builders (Embree's rtcBuildBVH) producing the portable layout of kernel/layout.h
// (traversal: kernel/bvh_traverse.h).
#pragma once

#include <cstdint>
#include <vector>

#include "cohort/kernel/layout.h"

namespace cohort::core {

struct BlasBuild {
  std::vector<KBvhNode> nodes;        // child indices relative to nodes[0]
  std::vector<KTriangle> triangles;   // the input triangles reordered to leaf order
  float sah_cost = 0.0f;
};

struct BvhBuildOptions {
  int max_leaf_size = 4;
  int threads = 0;                    // 0: every hardware thread
};

// Binned-SAH BLAS (Embree's rtcBuildBVH, multithreaded) over triangles whose vertex indices point into
// `vertices`. The same tree for any thread count. No triangles give no nodes.
BlasBuild build_blas(const std::vector<KVertex>& vertices, const std::vector<KTriangle>& triangles,
                     const BvhBuildOptions& options = {});

// Refit in place after vertices moved (same topology); returns the new SAH cost.
float refit_blas(const std::vector<KVertex>& vertices, BlasBuild& blas);

// Refitting keeps the topology, whose quality decays as a mesh deforms: rebuild once the refit SAH
// cost exceeds the freshly built one by `threshold`.
bool blas_needs_rebuild(float built_sah, float refit_sah, float threshold = 1.5f);

// TLAS over instances: `instances` is reordered to leaf order; blas_roots[i] is the root node of BLAS i
// (its object-space box). No instances give no nodes; traversal treats that as an empty scene.
std::vector<KBvhNode> build_tlas(std::vector<KInstance>& instances, const std::vector<KBvhNode>& blas_roots);

// Refit a TLAS from build_tlas in place after instances moved: the same instances in the same (leaf)
// order on the same BLASes, only their transforms changed. Returns the new SAH cost; as with BLASes,
// rebuild once tlas quality has decayed (blas_needs_rebuild with the built SAH).
float refit_tlas(const std::vector<KInstance>& instances, const std::vector<KBvhNode>& blas_roots,
                 std::vector<KBvhNode>& nodes);

// SAH cost of a built tree (traversal cost 1, intersection cost 1 per primitive), for quality checks.
float sah_cost(const std::vector<KBvhNode>& nodes);

}  // namespace cohort::core
