// Skinned characters on the GPU (kernel/skinning.h compiled as CUDA): one thread per vertex for the
// positions, then the normals; the BLAS refit runs its leaves one thread each, then a single thread
// sweeps the inner nodes bottom-up. Everything is queued on the tracer's stream, in order.
#pragma once

#include <cuda_runtime.h>

#include "cohort/kernel/skinning.h"

namespace cohort::tracers {

void launch_skinning(KVertex* vertices, const KSkinVertex* skin_vertices, const KSkinWeight* weights,
                     const KSkinTriangle* adjacency, const KJoint* joints, const KSkin& skin, KBvhNode* blas_nodes,
                     const KTriangle* triangles, const KBlas& blas, cudaStream_t stream);

}  // namespace cohort::tracers
