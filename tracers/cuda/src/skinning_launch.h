// Skinned characters on the GPU (kernel/skinning.h compiled as CUDA): one thread per vertex for the
// positions, one per triangle for its face, then one per vertex for the normals; the BLAS refit runs its leaves one thread each, then a single thread
// sweeps the inner nodes bottom-up. Everything is queued on the tracer's stream, in order.
#pragma once

#include <cuda_runtime.h>

#include "cohort/kernel/skinning.h"

namespace cohort::tracers {

struct SkinBuffers {   // device pointers to the scene's skin pools
  const KSkinVertex* skin_vertices;
  const KSkinWeight* weights;
  const KSkinTriangle* triangles;
  const kuint* adjacency;
  KSkinFace* faces;
  const KJoint* joints;
};

void launch_skinning(KVertex* vertices, const SkinBuffers& pools, const KSkin& skin, KBvhNode* blas_nodes,
                     const KTriangle* triangles, const KBlas& blas, cudaStream_t stream);

}  // namespace cohort::tracers
