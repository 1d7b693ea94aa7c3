/* A wavefront's walk kernels, per pixel, written once for the CUDA tracer (wavefront_walk.cu) and the OpenCL
 * one (wavefront_walk.cl): kernels that only walk rays through the BVH, apart from the shading
 * (wave_shade.h), so that they run at a register count of their own. The kernels index the pixel, call one
 * of these and count its rays. Each returns whether the pixel walked any (its rays are in ctx); x, y: the
 * pixel; in_band: the work item has one; p: where the band and the scratch hold it (one entry a band pixel).
 * integrator.h must be included first. */
#ifndef COHORT_KERNEL_WAVE_WALK_H
#define COHORT_KERNEL_WAVE_WALK_H

/* A sample's camera ray: its first hit in hits[p] (instance K_NONE: a miss; the shading kernel begins the
 * path). records: the frame's first-hit records, cleared here (the first sample's; else null), as
 * k_trace_path does. Pixels the sparse pattern of dynamic resolution leaves out trace nothing (the shading
 * kernel paints them). */
KFN int k_wave_camera_walk_pixel(KTraceCtx* ctx, const KFrameParams* params, const KCamera* camera, kuint x, kuint y,
                                 int in_band, size_t p, kuint sample, KGLOBAL KHit* hits,
                                 KGLOBAL KPathFirstHit* records) {
  int traces = in_band && k_pixel_traces_path(params->path_pixels, params->path_phase, x, y);
  if (traces) {
    if (records) k_record_first_hit(records + p, K_NONE, 0u, 0u);
    KRng rng;
    KVec3 dir = k_camera_sample(params, camera, x, y, sample, &rng);
    KHit hit;
    hit.cost = 0u;
    if (!k_trace_closest(ctx, v3_load(camera->origin), dir, K_INF, K_RAY_PRIMARY, &hit)) hit.instance = K_NONE;
    hits[p] = hit;
  }
  return traces;
}

/* A live path's bounce ray: its hit in hits[p] (instance K_NONE: a miss) for the shading kernel. */
KFN int k_wave_bounce_walk_pixel(KTraceCtx* ctx, int in_band, size_t p, KGLOBAL const KPathState* states,
                                 KGLOBAL KHit* hits, KGLOBAL const kuint* active) {
  int inside = in_band && (active[p] & K_WAVE_LIVE);
  if (inside) {
    KGLOBAL const KPathState* s = states + p;
    KHit hit;
    hit.cost = 0u;
    if (!k_trace_closest(ctx, s->org, s->dir, K_INF, K_RAY_PRIMARY, &hit)) hit.instance = K_NONE;
    hits[p] = hit;
  }
  return inside;
}

/* The vertex of pixel p once its shadow rays are walked (count: its vertex's ray_count, read before the
 * walks; visible: bit k set where nothing blocks slot k's ray; flags: the pixel's `active` flags before): the visible ones' values added in their order and the
 * vertex's light to its path's radiance (k_vertex_light_sum, the integrator's order of additions), a path
 * that ended there finished into the band. The second half of k_wave_shadow_walk_pixel; the Embree tracer
 * calls it after walking a tile's shadow rays together in packets (tracers/embree_cpu). */
KFN void k_wave_shadow_finish_pixel(const KFrameParams* params, size_t p, kuint sample, kuint flags, kuint count,
                                    kuint visible, KGLOBAL float* band, KGLOBAL KPathState* states,
                                    KGLOBAL kuint* active, KGLOBAL const KVertexLight* vertex_lights, KGLOBAL const KShadowRay* shadow_rays,
                                    kuint shadow_stride) {
  KGLOBAL const KShadowRay* rays = shadow_rays + p;
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
    k_wave_finish_sample(band, p, radiance, sample, params);
  }
}

/* The shadow rays a shading kernel left in the pixel's slots (shadow-ray slot k at
 * shadow_rays[k * shadow_stride + p]): each walked, then the vertex finished (k_wave_shadow_finish_pixel).
 * Only a bit per ray is carried through the walks, and the vertex is read after them, to keep its sums out
 * of the walk's registers (spills otherwise, on CUDA). */
KFN int k_wave_shadow_walk_pixel(KTraceCtx* ctx, const KFrameParams* params, int in_band, size_t p, kuint sample,
                                 KGLOBAL float* band, KGLOBAL KPathState* states, KGLOBAL kuint* active,
                                 KGLOBAL const KVertexLight* vertex_lights, KGLOBAL const KShadowRay* shadow_rays,
                                 kuint shadow_stride) {
  kuint flags = in_band ? active[p] : 0u;
  int inside = (flags & K_WAVE_SHADOWS_OUT) != 0u;
  if (inside) {
    KGLOBAL const KShadowRay* rays = shadow_rays + p;
    kuint count = vertex_lights[p].ray_count; /* at most K_SHADOW_QUEUE_MAX */
    kuint visible = 0u;
    for (kuint k = 0u; k < count; ++k) {
      KShadowRay ray = rays[(size_t)k * shadow_stride];
      if (k_shadow_ray_visible(ctx, &ray)) visible |= 1u << k;
    }
    k_wave_shadow_finish_pixel(params, p, sample, flags, count, visible, band, states, active, vertex_lights,
                               shadow_rays, shadow_stride);
  }
  return inside;
}

#endif
