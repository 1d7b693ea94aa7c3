// Skinned characters on the GPU (kernel/skinning.h compiled as CUDA): one thread per vertex for the
// positions, one per triangle for its face, then one per vertex for the normals. The BLAS refit runs
// bottom-up in parallel: a thread per leaf refits it and climbs; at each inner node the first child's
// thread to arrive stops and the second refits the node and goes on (an arrival counter per node), so
// every level is refit as soon as both its children are. Everything is queued on the tracer's stream, in
// order.
#pragma once

#include <cuda_runtime.h>

#include "cohort/kernel/skinning.h"
#include "cohort/kernel/bvh_traverse.h"

namespace cohort::tracers {

struct SkinBuffers {   // device pointers to the scene's skin pools
  const KSkinVertex* skin_vertices;
  const KSkinWeight* weights;
  const KSkinTriangle* triangles;
  const kuint* adjacency;
  KSkinFace* faces;
  const KJoint* joints;
};

struct RefitScratch {  // two uints per node of the largest skinned BLAS: parent and arrival count
  kuint* parent;
  kuint* arrivals;
};

// `edges` (KTriangleEdges parallel to the triangles, or null): the BLAS's triangles' edges follow the pose.
void launch_skinning(KVertex* vertices, const SkinBuffers& pools, const KSkin& skin, KBvhNode* blas_nodes,
                     const KTriangle* triangles, KTriangleEdges* edges, const KBlas& blas, const RefitScratch& scratch,
                     cudaStream_t stream);

// edges[first, first + count) from the triangles and vertices on the device.
void launch_triangle_edges(KTriangleEdges* edges, const KTriangle* triangles, const KVertex* vertices, size_t first,
                           size_t count, cudaStream_t stream);

}  // namespace cohort::tracers
