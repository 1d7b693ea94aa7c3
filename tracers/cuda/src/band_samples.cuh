// A finished path's sample into the band, shared by the CUDA tracer's kernels (render_band.cu,
// wavefront_walk.cu).
#pragma once

#include <cuda_runtime.h>

#include "cohort/kernel/layout.h"
#include "cohort/kernel/path_pattern.h"
#include "cohort/kernel/vec.h"

namespace cohort::tracers {

// A finished path's radiance into its pixel: the mean over the frame's samples, sample by sample.
__device__ inline void finish_sample(float4* band, size_t p, KVec3 radiance, kuint sample, const KFrameParams& params) {
  const float inv_spp = 1.0f / float(k_paths_per_pixel(params.spp));
  float4 c = make_float4(radiance.x * inv_spp, radiance.y * inv_spp, radiance.z * inv_spp, 1.0f);
  if (sample > 0u) {
    const float4 sum = band[p];
    c = make_float4(sum.x + c.x, sum.y + c.y, sum.z + c.z, 1.0f);
  }
  band[p] = c;
}

}  // namespace cohort::tracers
