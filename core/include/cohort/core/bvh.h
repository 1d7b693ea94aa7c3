// BVH builders producing the portable layout of kernel/layout.h (traversal: kernel/bvh_traverse.h).
#pragma once

#include <cstdint>
#include <vector>

#include "kernel/layout.h"

namespace cohort::core {

struct BlasBuild {
  std::vector<KBvhNode> nodes;        // child indices relative to nodes[0]
  std::vector<KTriangle> triangles;   // the input triangles reordered to leaf order
  float sah_cost = 0.0f;
};

struct BvhBuildOptions {
  int bins = 16;
  int max_leaf_size = 4;
  int threads = 0;                    // 0: hardware concurrency
};

// Binned-SAH BLAS over triangles whose vertex indices point into `vertices`.
BlasBuild build_blas(const std::vector<KVertex>& vertices, const std::vector<KTriangle>& triangles,
                     const BvhBuildOptions& options = {});

// Refit in place after vertices moved (same topology); returns the new SAH cost.
float refit_blas(const std::vector<KVertex>& vertices, BlasBuild& blas);

// TLAS over instances: `instances` is reordered to leaf order; blas_bounds[i] is the object-space
// root box of BLAS i (bmin, bmax).
std::vector<KBvhNode> build_tlas(std::vector<KInstance>& instances, const std::vector<KBvhNode>& blas_roots);

// SAH cost of a built tree (traversal cost 1, intersection cost 1 per primitive), for quality checks.
float sah_cost(const std::vector<KBvhNode>& nodes);

}  // namespace cohort::core
