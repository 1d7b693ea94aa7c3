// K_LIGHTS_DENSE's path kernels (render_band_kernels.cuh, K_LIGHTS_DENSE_BUILD 2): the same integrator as
// render_band.cu's, with the dense pick as its only light sampling, so that the other ways' kernels do not
// carry its code (docs/integrator.md, "Dense rooms"). render_band.cu launches these for frames that ask
// for it.
#include <cuda_runtime.h>

#define K_CUDA_DEVICE_ONLY 1
#define K_BVH_TRIANGLE_EDGES 1
#define K_LIGHTS_DENSE_BUILD 2
// This translation unit's own copy of the texel texture (render_band.cu's set_texel_texture sets it).
static __constant__ cudaTextureObject_t cohort_dense_texel_texture;
#define K_TEXEL_LOAD(texels, index) tex1Dfetch<unsigned int>(cohort_dense_texel_texture, (int)(index))

#include "cohort/kernel/trace_bvh.h"
#include "cohort/kernel/integrator.h"
#include "ray_counting.cuh"
#include "render_band_launch.h"

namespace cohort::tracers::dense {

#include "render_band_kernels.cuh"

void set_texel_texture(cudaTextureObject_t texture) {
  COHORT_CUDA(cudaMemcpyToSymbol(cohort_dense_texel_texture, &texture, sizeof texture));
}

}  // namespace cohort::tracers::dense
