/* The wavefront's walks (wavefront.cl has the sequence, wavefront_shade.cl the shading): kernels that only
 * walk rays through the BVH, a program of their own so that NVIDIA's compiler can cap its registers
 * (-cl-nv-maxrregcount, OpenCLTracer::Options::walk_registers) apart from the shading kernels': the CUDA
 * tracer's walks run at 64 registers, twice the megakernel's occupancy, to hide the memory latency of
 * incoherent bounce rays. The build inlines the #includes (embed_kernel.cmake). */
#include "cohort/kernel/trace_bvh.h"
#include "cohort/kernel/integrator.h"
#include "wavefront.cl"

/* A sample's camera rays: each pixel's first hit in `hits` (instance K_NONE: a miss; the shading kernel
 * begins the paths). The first sample clears the first-hit records, as k_trace_path does. */
__kernel void cohort_wave_camera_walk(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  KWavePixel px = k_wave_pixel(&params, &camera);
  KTraceCtx ctx = k_wave_trace_ctx(COHORT_BAND_KERNEL_ARGS, &params);
  /* Pixels the sparse pattern of dynamic resolution leaves out trace nothing (the shading kernel paints them). */
  int traces = px.inside && k_pixel_traces_path(params.path_pixels, params.path_phase, px.x, px.y);
  if (traces) {
    if (first_hits && sample == 0u) k_record_first_hit(first_hits + px.index, K_NONE, 0u, 0u);
    KRng rng;
    KVec3 dir = k_camera_sample(&params, &camera, px.x, px.y, sample, &rng);
    KHit hit;
    hit.cost = 0u;
    if (!k_trace_closest(&ctx, v3_load(camera.origin), dir, K_INF, K_RAY_PRIMARY, &hit)) hit.instance = K_NONE;
    hits[px.index] = hit;
  }
  k_wave_count_rays(group_rows, row_rays, &ctx, traces, &px, &params);
}

/* The live paths' bounce rays: their hits (instance K_NONE: a miss) for the shading kernel. */
__kernel void cohort_wave_bounce_walk(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  KWavePixel px = k_wave_pixel(&params, &camera);
  int inside = px.inside && (active[px.index] & K_WAVE_LIVE);
  KTraceCtx ctx = k_wave_trace_ctx(COHORT_BAND_KERNEL_ARGS, &params);
  if (inside) {
    KVec3 org = states[px.index].org, dir = states[px.index].dir;
    KHit hit;
    hit.cost = 0u;
    if (!k_trace_closest(&ctx, org, dir, K_INF, K_RAY_PRIMARY, &hit)) hit.instance = K_NONE;
    hits[px.index] = hit;
  }
  k_wave_count_rays(group_rows, row_rays, &ctx, inside, &px, &params);
}

/* The shadow rays a shading kernel left: each vertex's rays walked, then the visible ones' values added in
 * their order and the vertex's light to its path's radiance (k_vertex_light_sum, the integrator's order of
 * additions), a path that ended there finished. Only a bit per ray is carried through the walks, and the
 * vertex is read after them, to keep its sums out of the walk's registers. */
__kernel void cohort_wave_shadow_walk(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  KWavePixel px = k_wave_pixel(&params, &camera);
  size_t p = px.index;
  kuint flags = px.inside ? active[p] : 0u;
  int inside = (flags & K_WAVE_SHADOWS_OUT) != 0u;
  KTraceCtx ctx = k_wave_trace_ctx(COHORT_BAND_KERNEL_ARGS, &params);
  if (inside) {
    __global const KShadowRay* rays = shadow_rays + p;
    kuint count = vertex_lights[p].ray_count;  /* at most K_SHADOW_QUEUE_MAX */
    kuint visible = 0u;
    for (kuint k = 0u; k < count; ++k) {
      KShadowRay ray = rays[(size_t)k * shadow_stride];
      if (k_shadow_ray_visible(&ctx, &ray)) visible |= 1u << k;
    }
    KVertexLight v = vertex_lights[p];
    for (kuint k = 0u; k < count; ++k)
      if (visible & (1u << k)) {
        KShadowRay ray = rays[(size_t)k * shadow_stride];
        k_shadow_ray_add(&v, &ray);
      }
    KVec3 radiance = v3_add(states[p].radiance, k_vertex_light_sum(&v));
    if (flags & K_WAVE_LIVE) {
      states[p].radiance = radiance;
      active[p] = K_WAVE_LIVE;
    } else {
      active[p] = 0u;
      k_wave_finish_sample(band_rgba, p, radiance, sample, &params);
    }
  }
  k_wave_count_rays(group_rows, row_rays, &ctx, inside, &px, &params);
}
