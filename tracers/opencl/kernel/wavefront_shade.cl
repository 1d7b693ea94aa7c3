/* The wavefront's shading kernels (wavefront.cl has the sequence): what the live paths' rays met, walked by
 * the walk kernels (wavefront_walk.cl), shaded up to each path's next bounce (k_path_segment: transparent
 * layers walked here), the paths left in memory for the next walk. Built into the main program, beside the
 * megakernel whose image they draw bit for bit. */
#include "wavefront.cl"

/* camera_rays: the camera rays' segment, whose paths begin here from the pixel (the camera walk kept only
 * the hits); records: that segment of the frame's first sample, recording first hits; shadow_walk: the
 * vertex's shadow rays left in the pixel's slots for the shadow walk (else walked here as they come). The
 * kernels below pass constants, so each keeps one way (as the CUDA tracer's template parameters do). */
KFN void k_wave_shade(COHORT_WAVE_KERNEL_PARAMS, __local uint* group_rows, int camera_rays, int records,
                      int shadow_walk) {
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  KWavePixel px = k_wave_pixel(&params, &camera);
  size_t p = px.index;
  int inside = px.inside && (camera_rays || (active[p] & K_WAVE_LIVE));
  KTraceCtx ctx = k_wave_trace_ctx(COHORT_BAND_KERNEL_ARGS, &params);
  if (camera_rays && inside && !k_pixel_traces_path(params.path_pixels, params.path_phase, px.x, px.y)) {
    /* Dynamic resolution's sparse pattern leaves this pixel out: black, at no cost (k_render_pixel's way). */
    active[p] = 0u;
    k_wave_finish_sample(band_rgba, p, v3s(0.0f), sample, &params);
    inside = 0;
  }
  if (inside) {
    KPathState s;
    if (camera_rays) {
      KRng rng;
      KVec3 dir = k_camera_sample(&params, &camera, px.x, px.y, sample, &rng);
      k_path_begin(&s, v3_load(camera.origin), dir, k_pixel_spread(&camera), rng);
    } else {
      s = states[p];
    }
    KHit hit = hits[p];
    KShadowQueue shadows = k_shadow_queue_inline();
    if (shadow_walk) {
      shadows.rays = shadow_rays + p;
      shadows.stride = shadow_stride;
      shadows.capacity = K_SHADOW_QUEUE_MAX;
    }
    KVertexLight vertex;
    int goes_on = k_path_segment(&ctx, &params, &s, &hit, records ? first_hits + p : 0, &shadows, &vertex);
    /* A vertex whose shadow rays are out waits for the shadow walk, which adds its light and finishes the
     * sample of a path that ended there. */
    int shadows_out = shadows.count > 0u;
    if (goes_on || shadows_out) states[p] = s;
    if (shadows_out) vertex_lights[p] = vertex;
    if (camera_rays || !goes_on || shadows_out)
      active[p] = (goes_on ? K_WAVE_LIVE : 0u) | (shadows_out ? K_WAVE_SHADOWS_OUT : 0u);
    if (!goes_on && !shadows_out) k_wave_finish_sample(band_rgba, p, s.radiance, sample, &params);
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
