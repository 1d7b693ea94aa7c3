// A finished path's sample into the band, shared by the CUDA tracer's kernels (render_band.cu,
// wavefront_walk.cu).
#pragma once

#include <cuda_runtime.h>

#include "cohort/kernel/layout.h"
#include "cohort/kernel/path_pattern.h"
#include "cohort/kernel/path_state.h"
#include "cohort/kernel/vec.h"

namespace cohort::tracers {

// A finished path's radiance into its pixel (kernel/path_state.h: summed, scaled at the last sample, as the
// megakernel and the OpenCL wavefront do).
__device__ inline void finish_sample(float4* band, size_t p, KVec3 radiance, kuint sample, const KFrameParams& params) {
  k_wave_finish_sample(reinterpret_cast<float*>(band), p, radiance, sample, &params);
}

}  // namespace cohort::tracers
