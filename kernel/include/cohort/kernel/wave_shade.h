/* A wavefront's shading kernel, per pixel, written once for the CUDA tracer (render_band_kernels.cuh's
 * wave_shade_kernel) and the OpenCL one (wavefront_shade.cl's k_wave_shade): what the walked ray of the
 * pixel's path met (hits[p], walked by a walk kernel), shaded up to the path's next bounce, the path left in
 * memory for the next walk (path_state.h). A kernel asks k_wave_shades, makes its trace context, then
 * k_wave_shade_begin; for a pixel it shades, k_path_segment between k_wave_path_load and
 * k_wave_path_store; then counts its rays. Pieces, not one function, for CUDA's spills (ptxas, sm_90, each
 * kernel's figures are main's with these): with the segment called inside one body function, a shading kernel
 * spilled up to 128 bytes more (the dense build's bounce kernel with the shadow walk, 200 -> 328 bytes of
 * stores); with k_wave_shades inside k_wave_shade_begin, after the trace context or before it, spill
 * stores and loads moved by -16 to +16 bytes. The segment is the kernel's own call: the CUDA tracer's goes
 * through a function of default inlining (render_band_kernels.cuh says why). integrator.h must be included
 * first.
 *
 * The kernels' choices are constants of each kernel, so that each keeps one way: camera_rays: the camera
 * rays' segment, whose paths begin here from the pixel (the camera walk kept only the hits); shadow_walk: the
 * vertex's shadow rays left in the pixel's slots for the shadow walk (else walked as they come). p: the
 * pixel's place in the band and the scratch (one entry a band pixel; shadow-ray slot k at
 * shadow_rays[k * shadow_stride + p]). */
#ifndef COHORT_KERNEL_WAVE_SHADE_H
#define COHORT_KERNEL_WAVE_SHADE_H

/* Whether the work item shades pixel p (in_band: it has a pixel): every pixel for the camera rays' segment,
 * else those whose path goes on. */
KFN int k_wave_shades(int in_band, size_t p, KGLOBAL const kuint* active, int camera_rays) {
  return in_band && (camera_rays || (active[p] & K_WAVE_LIVE));
}

/* Pixel (x, y) of the camera rays' segment that dynamic resolution's sparse pattern leaves out: black, at no
 * cost (k_render_pixel's way). Returns whether the pixel is still shaded. */
KFN int k_wave_shade_begin(const KFrameParams* params, kuint x, kuint y, int inside, size_t p, kuint sample,
                           KGLOBAL float* band, KGLOBAL kuint* active, int camera_rays) {
  if (camera_rays && inside && !k_pixel_traces_path(params->path_pixels, params->path_phase, x, y)) {
    active[p] = 0u;
    k_wave_finish_sample(band, p, v3s(0.0f), sample, params);
    inside = 0;
  }
  return inside;
}

/* The path of pixel (x, y) before its segment: begun from the camera (camera_rays) or as it waited; its
 * walked ray's hit; where its vertex's shadow rays go. */
KFN void k_wave_path_load(const KFrameParams* params, const KCamera* camera, kuint x, kuint y, size_t p,
                          kuint sample, KGLOBAL const KPathState* states, KGLOBAL const KHit* hits,
                          KGLOBAL KShadowRay* shadow_rays, kuint shadow_stride, int camera_rays, int shadow_walk,
                          KPathState* s, KHit* hit, KShadowQueue* shadows) {
  if (camera_rays) {
    KRng rng;
    KVec3 dir = k_camera_sample(params, camera, x, y, sample, &rng);
    k_path_begin(s, v3_load(camera->origin), dir, k_pixel_spread(camera), rng);
  } else {
    *s = states[p];
  }
  *hit = hits[p];
  /* The slots' capacity is a constant, so that each build keeps one way (the host gives a vertex all the
   * slots it needs, k_shadow_queue_slots). */
  *shadows = k_shadow_queue_inline();
  if (shadow_walk) {
    shadows->rays = shadow_rays + p;
    shadows->stride = shadow_stride;
    shadows->capacity = K_SHADOW_QUEUE_MAX;
  }
}

/* The path after its segment (goes_on: it bounced). A vertex whose shadow rays are out waits for the shadow
 * walk, which adds its light and finishes the sample of a path that ended there; else a path that ended
 * finishes its sample here. */
KFN void k_wave_path_store(const KFrameParams* params, size_t p, kuint sample, int goes_on, const KPathState* s,
                           const KShadowQueue* shadows, const KVertexLight* vertex, KGLOBAL float* band,
                           KGLOBAL KPathState* states, KGLOBAL kuint* active, KGLOBAL KVertexLight* vertex_lights,
                           int camera_rays) {
  int shadows_out = shadows->count > 0u;
  if (goes_on || shadows_out) states[p] = *s;
  if (shadows_out) vertex_lights[p] = *vertex;
  if (camera_rays || !goes_on || shadows_out)
    active[p] = (goes_on ? K_WAVE_LIVE : 0u) | (shadows_out ? K_WAVE_SHADOWS_OUT : 0u);
  if (!goes_on && !shadows_out) k_wave_finish_sample(band, p, s->radiance, sample, params);
}

#endif
