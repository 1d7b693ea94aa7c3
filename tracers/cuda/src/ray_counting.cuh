// What the CUDA tracer's band kernels share (render_band.cu, wavefront_walk.cu): where a thread's pixel lies
// in the band, a fresh trace context, and the ray counts.
#pragma once

#include <cuda_runtime.h>

#include "cohort/kernel/trace_bvh.h"

namespace cohort::tracers {

// A thread's pixel: blocks tile the band (row: within it; y: in the frame); `inside` where the band has it.
struct BandPixel {
  kuint x, row, y;
  bool inside;
  __device__ size_t index(const KCamera& camera) const { return size_t(row) * camera.width + x; }
};
__device__ inline BandPixel band_pixel(const KFrameParams& params, const KCamera& camera) {
  BandPixel p;
  p.x = blockIdx.x * blockDim.x + threadIdx.x;
  p.row = blockIdx.y * blockDim.y + threadIdx.y;
  p.y = params.row_begin + p.row;
  p.inside = p.x < camera.width && p.y < params.row_end;
  return p;
}
__device__ inline KTraceCtx fresh_trace_ctx(const KSceneView& scene) {
  KTraceCtx ctx;
  ctx.scene = scene;
  ctx.closest_rays = 0u;
  ctx.occlusion_rays = 0u;
  return ctx;
}

// The rays a thread traced, added up per warp: into ray_counts (closest, occlusion; may be null) and into
// row_rays, the rays per row of the band (the balancer's per-row work; may be null). Every lane of the warp
// calls it, inside the image or not; blocks are 16 wide, so a warp holds two rows.
__device__ inline void count_rays(const KTraceCtx& ctx, bool inside, kuint row, bool row_inside,
                           unsigned long long* ray_counts, unsigned* row_rays) {
  if (ray_counts) {
    unsigned closest = __reduce_add_sync(0xffffffffu, ctx.closest_rays);
    unsigned occlusion = __reduce_add_sync(0xffffffffu, ctx.occlusion_rays);
    if ((threadIdx.x + threadIdx.y * blockDim.x) % 32u == 0u) {
      atomicAdd(&ray_counts[0], (unsigned long long)closest);
      atomicAdd(&ray_counts[1], (unsigned long long)occlusion);
    }
  }
  if (row_rays) {
    const unsigned mine = inside ? ctx.closest_rays + ctx.occlusion_rays : 0u;
    const unsigned lane = (threadIdx.x + threadIdx.y * blockDim.x) % 32u;
    const unsigned low = __reduce_add_sync(0xffffffffu, lane < 16u ? mine : 0u);
    const unsigned high = __reduce_add_sync(0xffffffffu, lane >= 16u ? mine : 0u);
    const unsigned half = lane < 16u ? low : high;
    if ((lane == 0u || lane == 16u) && row_inside && half != 0u) atomicAdd(&row_rays[row], half);
  }
}

}  // namespace cohort::tracers
