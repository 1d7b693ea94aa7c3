// The wavefront's walks (render_band.cu has the shading): kernels that only walk rays through the BVH, with
// the walk inlined (one call site each) and at most 64 registers, so that twice the megakernel's warps hide
// the memory latency of incoherent bounce rays. Measured on one H100 (docs/integrator.md): the bounce walk
// outlined at its own 96 registers, 80 and 64: 9.13-9.17, 8.96-9.04 and 8.86-8.93 ms a 1080p frame of the
// large map; inlined at 64 registers 8.61; inlined at 72 and 79, 8.77-8.82.
#include <cuda_runtime.h>

#define K_CUDA_DEVICE_ONLY 1
#define K_BVH_TRIANGLE_EDGES 1
#define KFN_OUTLINED static __device__ __forceinline__
// This translation unit's own copy of the texel texture: alpha-tested surfaces are looked up mid-walk.
static __constant__ cudaTextureObject_t cohort_walk_texel_texture;
#define K_TEXEL_LOAD(texels, index) tex1Dfetch<unsigned int>(cohort_walk_texel_texture, (int)(index))

#include "cohort/kernel/trace_bvh.h"
#include "cohort/kernel/integrator.h"
#include "cohort/kernel/wave_walk.h"
#include "ray_counting.cuh"
#include "render_band_launch.h"

namespace cohort::tracers {

namespace {

// The bodies are kernel/wave_walk.h's (the OpenCL tracer's too).

// A sample's camera rays: each pixel's first hit in wave.hits (the shading kernel begins the paths).
__global__ void __launch_bounds__(128, 8) camera_walk_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                                             kuint sample, WavefrontScratch wave,
                                                             KPathFirstHit* records, unsigned long long* ray_counts,
                                                             unsigned* row_rays) {
  const BandPixel px = band_pixel(params, camera);
  KTraceCtx ctx = fresh_trace_ctx(scene);
  const bool traces = k_wave_camera_walk_pixel(&ctx, &params, &camera, px.x, px.y, px.inside, px.index(camera),
                                               sample, wave.hits, records);
  count_rays(ctx, traces, px.row, px.y < params.row_end, ray_counts, row_rays);
}

// The live paths' bounce rays: their hits (instance K_NONE: a miss) for the shading kernel.
__global__ void __launch_bounds__(128, 8) bounce_walk_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                                             WavefrontScratch wave, unsigned long long* ray_counts,
                                                             unsigned* row_rays) {
  const BandPixel px = band_pixel(params, camera);
  KTraceCtx ctx = fresh_trace_ctx(scene);
  const bool inside = k_wave_bounce_walk_pixel(&ctx, px.inside, px.index(camera), wave.states, wave.hits, wave.active);
  count_rays(ctx, inside, px.row, px.y < params.row_end, ray_counts, row_rays);
}

// The shadow rays a shading kernel left: each vertex's rays walked, its light added to its path's radiance,
// a path that ended there finished.
__global__ void __launch_bounds__(128, 8) shadow_walk_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                                             kuint sample, float4* band, WavefrontScratch wave,
                                                             unsigned long long* ray_counts, unsigned* row_rays) {
  const BandPixel px = band_pixel(params, camera);
  KTraceCtx ctx = fresh_trace_ctx(scene);
  const bool inside = k_wave_shadow_walk_pixel(&ctx, &params, px.inside, px.index(camera), sample,
                                               reinterpret_cast<float*>(band), wave.states, wave.active,
                                               wave.vertices, wave.shadow_rays, wave.shadow_stride);
  count_rays(ctx, inside, px.row, px.y < params.row_end, ray_counts, row_rays);
}

}  // namespace

void set_walk_texel_texture(cudaTextureObject_t texture) {
  COHORT_CUDA(cudaMemcpyToSymbol(cohort_walk_texel_texture, &texture, sizeof texture));
}

void launch_wave_camera_walk(dim3 grid, dim3 block, const KSceneView& scene, const KFrameParams& params,
                             const KCamera& camera, kuint sample, const WavefrontScratch& wave, KPathFirstHit* records,
                             unsigned long long* ray_counts, unsigned* row_rays, cudaStream_t stream) {
  camera_walk_kernel<<<grid, block, 0, stream>>>(scene, params, camera, sample, wave, records, ray_counts, row_rays);
}

void launch_wave_bounce_walk(dim3 grid, dim3 block, const KSceneView& scene, const KFrameParams& params,
                             const KCamera& camera, const WavefrontScratch& wave, unsigned long long* ray_counts,
                             unsigned* row_rays, cudaStream_t stream) {
  bounce_walk_kernel<<<grid, block, 0, stream>>>(scene, params, camera, wave, ray_counts, row_rays);
}

void launch_wave_shadow_walk(dim3 grid, dim3 block, const KSceneView& scene, const KFrameParams& params,
                             const KCamera& camera, kuint sample, float4* band, const WavefrontScratch& wave,
                             unsigned long long* ray_counts, unsigned* row_rays, cudaStream_t stream) {
  shadow_walk_kernel<<<grid, block, 0, stream>>>(scene, params, camera, sample, band, wave, ray_counts, row_rays);
}

}  // namespace cohort::tracers
