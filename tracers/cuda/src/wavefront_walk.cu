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
#include "band_samples.cuh"
#include "ray_counting.cuh"
#include "render_band_launch.h"

namespace cohort::tracers {

namespace {

// A sample's camera rays: each pixel's first hit in wave.hits (the shading kernel begins the paths).
__global__ void __launch_bounds__(128, 8) camera_walk_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                                             kuint sample, WavefrontScratch wave,
                                                             KPathFirstHit* records, unsigned long long* ray_counts,
                                                             unsigned* row_rays) {
  const BandPixel px = band_pixel(params, camera);
  KTraceCtx ctx = fresh_trace_ctx(scene);
  // Pixels the sparse pattern of dynamic resolution leaves out trace nothing (the shading kernel paints them).
  const bool traces = px.inside && k_pixel_traces_path(params.path_pixels, params.path_phase, px.x, px.y);
  if (traces) {
    const size_t p = px.index(camera);
    if (records) k_record_first_hit(records + p, K_NONE, 0u, 0u);
    KRng rng;
    const KVec3 dir = k_camera_sample(&params, &camera, px.x, px.y, sample, &rng);
    KHit hit;
    hit.cost = 0u;
    if (!k_trace_closest(&ctx, v3_load(camera.origin), dir, K_INF, K_RAY_PRIMARY, &hit)) hit.instance = K_NONE;
    wave.hits[p] = hit;
  }
  count_rays(ctx, traces, px.row, px.y < params.row_end, ray_counts, row_rays);
}

// The live paths' bounce rays: their hits (instance K_NONE: a miss) for the shading kernel.
__global__ void __launch_bounds__(128, 8) bounce_walk_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                                             WavefrontScratch wave, unsigned long long* ray_counts,
                                                             unsigned* row_rays) {
  const BandPixel px = band_pixel(params, camera);
  const size_t p = px.index(camera);
  const bool inside = px.inside && (wave.active[p] & K_WAVE_LIVE);
  KTraceCtx ctx = fresh_trace_ctx(scene);
  if (inside) {
    const KPathState* s = wave.states + p;
    KHit hit;
    hit.cost = 0u;
    if (!k_trace_closest(&ctx, s->org, s->dir, K_INF, K_RAY_PRIMARY, &hit)) hit.instance = K_NONE;
    wave.hits[p] = hit;
  }
  count_rays(ctx, inside, px.row, px.y < params.row_end, ray_counts, row_rays);
}

// The shadow rays a shading kernel left: each vertex's rays walked, then the visible ones' values added in
// their order and the vertex's light to its path's radiance (k_vertex_light_sum, the integrator's order of
// additions), a path that ended there finished. Only a bit per ray is carried through the walks, and the
// vertex is read after them, to keep its sums out of the walk's registers (spills otherwise).
__global__ void __launch_bounds__(128, 8) shadow_walk_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                                             kuint sample, float4* band, WavefrontScratch wave,
                                                             unsigned long long* ray_counts, unsigned* row_rays) {
  const BandPixel px = band_pixel(params, camera);
  const size_t p = px.index(camera);
  const kuint flags = px.inside ? wave.active[p] : 0u;
  const bool inside = (flags & K_WAVE_SHADOWS_OUT) != 0u;
  KTraceCtx ctx = fresh_trace_ctx(scene);
  if (inside) {
    const KShadowRay* rays = wave.shadow_rays + p;
    const kuint count = wave.vertices[p].ray_count;  // at most K_SHADOW_QUEUE_MAX
    kuint visible = 0u;
    for (kuint k = 0u; k < count; ++k) {
      const KShadowRay ray = rays[size_t(k) * wave.shadow_stride];
      if (k_shadow_ray_visible(&ctx, &ray)) visible |= 1u << k;
    }
    KVertexLight v = wave.vertices[p];
    for (kuint k = 0u; k < count; ++k)
      if (visible & (1u << k)) {
        const KShadowRay ray = rays[size_t(k) * wave.shadow_stride];
        k_shadow_ray_add(&v, &ray);
      }
    const KVec3 radiance = v3_add(wave.states[p].radiance, k_vertex_light_sum(&v));
    if (flags & K_WAVE_LIVE) {
      wave.states[p].radiance = radiance;
      wave.active[p] = K_WAVE_LIVE;
    } else {
      wave.active[p] = 0u;
      finish_sample(band, p, radiance, sample, params);
    }
  }
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
