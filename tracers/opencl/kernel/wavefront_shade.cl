/* The wavefront's shading kernels (wavefront.cl has the sequence): what the live paths' rays met, walked by
 * the walk kernels (wavefront_walk.cl), shaded up to each path's next bounce (k_path_segment: transparent
 * layers walked here), the paths left in memory for the next walk. Built into the main program, beside the
 * megakernel whose image they draw bit for bit. */
#include "wavefront.cl"
#include "cohort/kernel/wave_shade.h"

/* kernel/wave_shade.h has the pixel's shading (the CUDA tracer's too); camera_rays, records and shadow_walk
 * are its choices, constants in the kernels below, so that each keeps one way (as the CUDA tracer's template
 * parameters do). */
KFN void k_wave_shade(COHORT_WAVE_KERNEL_PARAMS, __local uint* group_rows, int camera_rays, int records,
                      int shadow_walk) {
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  KWavePixel px = k_wave_pixel(&params, &camera);
  size_t p = px.index;
  int inside = k_wave_shades(px.inside, p, active, camera_rays);
  KTraceCtx ctx = k_wave_trace_ctx(COHORT_BAND_KERNEL_ARGS, &params);
  inside = k_wave_shade_begin(&params, px.x, px.y, inside, p, sample, band_rgba, active, camera_rays);
  if (inside) {
    KPathState s;
    KHit hit;
    KShadowQueue shadows;
    k_wave_path_load(&params, &camera, px.x, px.y, p, sample, states, hits, shadow_rays, shadow_stride, camera_rays,
                     shadow_walk, &s, &hit, &shadows);
    KVertexLight vertex;
    int goes_on = k_path_segment(&ctx, &params, &s, &hit, records ? first_hits + p : 0, &shadows, &vertex);
    k_wave_path_store(&params, p, sample, goes_on, &s, &shadows, &vertex, band_rgba, states, active, vertex_lights,
                      camera_rays);
  }
  k_wave_count_rays(group_rows, row_rays, &ctx, inside, &px, &params);
}

/* The builds the host picks from: camera rays (with first-hit records) or bounce rays; with the shadow
 * walk (`_shadow_walk`) or the shadow rays walked here (a frame whose vertices may emit more rays than
 * their slots, k_shadow_queue_slots, or the shadow walk switched off). 8x8 work groups. */
__kernel void cohort_wave_shade_camera(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  k_wave_shade(COHORT_WAVE_KERNEL_ARGS, group_rows, 1, 0, 0);
}
__kernel void cohort_wave_shade_camera_first_hits(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  k_wave_shade(COHORT_WAVE_KERNEL_ARGS, group_rows, 1, 1, 0);
}
__kernel void cohort_wave_shade_bounce(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  k_wave_shade(COHORT_WAVE_KERNEL_ARGS, group_rows, 0, 0, 0);
}
__kernel void cohort_wave_shade_camera_shadow_walk(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  k_wave_shade(COHORT_WAVE_KERNEL_ARGS, group_rows, 1, 0, 1);
}
__kernel void cohort_wave_shade_camera_first_hits_shadow_walk(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  k_wave_shade(COHORT_WAVE_KERNEL_ARGS, group_rows, 1, 1, 1);
}
__kernel void cohort_wave_shade_bounce_shadow_walk(COHORT_WAVE_KERNEL_PARAMS) {
  __local uint group_rows[8];
  k_wave_shade(COHORT_WAVE_KERNEL_ARGS, group_rows, 0, 0, 1);
}
