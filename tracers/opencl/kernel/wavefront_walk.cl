/* The wavefront's walks (wavefront.cl has the sequence, wavefront_shade.cl the shading): kernels that only
 * walk rays through the BVH, a program of their own so that NVIDIA's compiler can cap its registers
 * (-cl-nv-maxrregcount, OpenCLTracer::Options::walk_registers) apart from the shading kernels': the CUDA
 * tracer's walks run at 64 registers, twice the megakernel's occupancy, to hide the memory latency of
 * incoherent bounce rays. The build inlines the #includes (embed_kernel.cmake). */
#include "cohort/kernel/trace_bvh.h"
#include "cohort/kernel/integrator.h"
#include "cohort/kernel/wave_walk.h"
#include "wavefront.cl"

/* The bodies are kernel/wave_walk.h's (the CUDA tracer's too). */

/* A sample's camera rays: each pixel's first hit in `hits` (the shading kernel begins the paths); the first
 * sample clears the first-hit records. */
__kernel void cohort_wave_camera_walk(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  KWavePixel px = k_wave_pixel(&params, &camera);
  KTraceCtx ctx = k_wave_trace_ctx(COHORT_BAND_KERNEL_ARGS, &params);
  int traces = k_wave_camera_walk_pixel(&ctx, &params, &camera, px.x, px.y, px.inside, px.index, sample, hits,
                                        sample == 0u ? first_hits : 0);
  k_wave_count_rays(group_rows, row_rays, &ctx, traces, &px, &params);
}

/* The live paths' bounce rays: their hits (instance K_NONE: a miss) for the shading kernel. */
__kernel void cohort_wave_bounce_walk(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  KWavePixel px = k_wave_pixel(&params, &camera);
  KTraceCtx ctx = k_wave_trace_ctx(COHORT_BAND_KERNEL_ARGS, &params);
  int inside = k_wave_bounce_walk_pixel(&ctx, px.inside, px.index, states, hits, active);
  k_wave_count_rays(group_rows, row_rays, &ctx, inside, &px, &params);
}

/* The shadow rays a shading kernel left: each vertex's rays walked, its light added to its path's radiance,
 * a path that ended there finished. */
__kernel void cohort_wave_shadow_walk(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  KWavePixel px = k_wave_pixel(&params, &camera);
  KTraceCtx ctx = k_wave_trace_ctx(COHORT_BAND_KERNEL_ARGS, &params);
  int inside = k_wave_shadow_walk_pixel(&ctx, &params, px.inside, px.index, sample, band_rgba, states, active,
                                        vertex_lights, shadow_rays, shadow_stride);
  k_wave_count_rays(group_rows, row_rays, &ctx, inside, &px, &params);
}
