/* The path-tracing integrator, written once for every tracer. It does not know how rays are traced:
 * before including this header the includer defines
 *
 *   KTraceCtx                        any type; K_CTX_SCENE(ctx) must yield a `const KSceneView*`
 *                                    (default: &(ctx)->scene)
 *   int k_trace_closest(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask, KHit* hit)
 *       nearest hit in (0, tmax) on instances whose mask shares a bit with ray_mask, skipping
 *       candidates for which k_hit_transmittance(scene, inst, tri, u, v, 0) != 0; returns 1 on a hit
 *   int k_trace_occluded(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask)
 *       1 when any candidate with k_hit_transmittance(scene, inst, tri, u, v, 1) == 0 lies in (0, tmax)
 *
 * (Embree: rtcIntersect1/rtcOccluded1 with filter functions; OpenCL/CUDA: bvh_traverse.h.)
 * Entry point: k_render_pixel(ctx, params, camera, x, y) -> linear RGB averaged over params->spp. */
#ifndef COHORT_KERNEL_INTEGRATOR_H
#define COHORT_KERNEL_INTEGRATOR_H
#include "lights.h"
#include "rng.h"

#ifndef K_CTX_SCENE
#define K_CTX_SCENE(ctx) (&(ctx)->scene)
#endif

#define K_MAX_LAYERS 16   /* transparent layers a ray may cross without consuming a bounce */
#define K_REGULARIZED_ROUGHNESS 0.5f  /* least roughness of surfaces reached by a bounce */
#define K_BOUNCE_SPREAD 0.1f          /* ray-cone widening per bounce (radians), for mip selection */

KFN float k_ray_epsilon(KVec3 p) {
  return 1e-3f + 2e-5f * k_fmax(k_fabs(p.x), k_fmax(k_fabs(p.y), k_fabs(p.z)));
}

/* Camera ray through pixel (x + jx, y + jy); y grows downward. */
KFN KVec3 k_camera_direction(const KCamera* cam, float px, float py) {
  float sx = (2.0f * px / (float)cam->width - 1.0f) * cam->tan_half_fov_x;
  float sy = (1.0f - 2.0f * py / (float)cam->height) * cam->tan_half_fov_y;
  KVec3 d = v3_add(v3_load(cam->forward), v3_add(v3_scale(v3_load(cam->right), sx), v3_scale(v3_load(cam->up), sy)));
  return v3_normalize(d);
}

/* One shadow ray toward a point jittered over the light's extent: 1 when the light is visible. */
KFN int k_light_visible(KTraceCtx* ctx, const KFrameParams* params, const KSurface* sf, KGLOBAL const KLight* light,
                        float u1, float u2) {
  if (light->flags & K_LIGHT_NO_SHADOWS) return 1;
  float dist;
  KVec3 dir = k_light_jittered_direction(light, sf->position, params->soft_shadow_scale, u1, u2, &dist);
  if (v3_dot(dir, sf->geo_normal) <= 0.0f) return 0;
  float eps = k_ray_epsilon(sf->position);
  KVec3 org = v3_madd(sf->position, sf->geo_normal, eps);
  float tmax = dist < K_INF ? dist - 2.0f * eps : K_INF;
  return tmax <= 0.0f || !k_trace_occluded(ctx, org, dir, tmax, K_RAY_SHADOW);
}

/* Next-event estimation. light_samples == 0: every light that reaches the point, one shadow ray each
 * (as Doom 3 draws every interaction; lowest noise where few lights overlap). Otherwise, per light
 * sample, one light picked in proportion to its unshadowed contribution (so the many lights that
 * cannot reach this point cost no rays) and one shadow ray toward it. */
KFN KVec3 k_direct_lighting(KTraceCtx* ctx, const KFrameParams* params, const KSurface* sf, KVec3 wo, KRng* rng) {
  const KSceneView* scene = K_CTX_SCENE(ctx);
  KVec3 sum = v3s(0.0f);
  if (params->light_samples == 0u) {
    for (kuint i = 0u; i < scene->light_count; ++i) {
      KGLOBAL const KLight* light = &scene->lights[i];
      KVec3 c = k_light_unshadowed(scene, light, sf, wo, params->spec_boost);
      if (v3_max_component(c) <= 0.0f) continue;
      float u1 = k_rng_next(rng), u2 = k_rng_next(rng);
      if (k_light_visible(ctx, params, sf, light, u1, u2)) sum = v3_add(sum, c);
    }
    return sum;
  }
  kuint samples = params->light_samples;
  for (kuint k = 0u; k < samples; ++k) {
    float total = 0.0f, chosen_weight = 0.0f;
    kuint chosen = K_NONE;
    KVec3 chosen_contrib = v3s(0.0f);
    float u_pick = k_rng_next(rng);
    for (kuint i = 0u; i < scene->light_count; ++i) {
      KVec3 c = k_light_unshadowed(scene, &scene->lights[i], sf, wo, params->spec_boost);
      float w = v3_luminance(c);
      if (w <= 0.0f) continue;
      total += w;
      /* Single-slot reservoir: keep light i with probability w / total. */
      if (u_pick * total < w) {
        chosen = i;
        chosen_weight = w;
        chosen_contrib = c;
        u_pick = u_pick * total / w;
      } else {
        u_pick = (u_pick * total - w) / (total - w);
      }
    }
    float u1 = k_rng_next(rng), u2 = k_rng_next(rng);
    if (chosen == K_NONE) continue;
    if (!k_light_visible(ctx, params, sf, &scene->lights[chosen], u1, u2)) continue;
    sum = v3_add(sum, v3_scale(chosen_contrib, total / chosen_weight));
  }
  return v3_scale(sum, 1.0f / (float)samples);
}

KFN KVec3 k_clamp_radiance(KVec3 c, float limit) {
  if (limit <= 0.0f) return c;
  float m = v3_max_component(c);
  return m > limit ? v3_scale(c, limit / m) : c;
}

KFN KVec3 k_heat_color(float x) {
  x = k_saturate(x);
  return v3(k_saturate(2.0f * x - 1.0f), 1.0f - k_fabs(2.0f * x - 1.0f), k_saturate(1.0f - 2.0f * x));
}

KFN KVec3 k_id_color(kuint id) {
  kuint h = k_pcg_hash(id);
  return v3((float)(h & 0xFFu) / 255.0f, (float)((h >> 8) & 0xFFu) / 255.0f, (float)((h >> 16) & 0xFFu) / 255.0f);
}

/* Radiance along one camera ray; pixel_spread is the angle one pixel subtends (for mip selection). */
KFN KVec3 k_trace_path(KTraceCtx* ctx, const KFrameParams* params, KVec3 org, KVec3 dir, float pixel_spread,
                       KRng* rng) {
  const KSceneView* scene = K_CTX_SCENE(ctx);
  KVec3 radiance = v3s(0.0f), throughput = v3s(1.0f);
  float cone_width = 0.0f, spread = pixel_spread;
  kuint bounce = 0u, layers = 0u;
  float tmax = K_INF;
  for (;;) {
    KHit hit;
    hit.cost = 0u;
    if (!k_trace_closest(ctx, org, dir, tmax, K_RAY_PRIMARY, &hit)) {
      if (params->mode == K_MODE_BVH && bounce == 0u) radiance = k_heat_color((float)hit.cost / 200.0f);
      break;
    }
    if (params->mode == K_MODE_BVH) { radiance = k_heat_color((float)hit.cost / 200.0f); break; }
    if (params->mode == K_MODE_TRIANGLES) { radiance = k_id_color(hit.triangle); break; }
    cone_width += spread * hit.t;
    KSurface sf = k_surface_eval(scene, hit, org, dir, cone_width);
    KVec3 wo = v3_neg(dir);

    if (sf.blend != K_BLEND_OPAQUE) {
      /* Transparent layers: shade the layer, carry on through it without consuming a bounce. */
      if (sf.blend == K_BLEND_ADDITIVE) {
        radiance = v3_add(radiance, v3_mul(throughput, v3_add(sf.albedo, sf.emission)));
      } else if (sf.blend == K_BLEND_MODULATE) {
        throughput = v3_mul(throughput, sf.albedo);
      } else {
        radiance = v3_add(radiance, v3_scale(v3_mul(throughput, sf.albedo), sf.alpha));
        throughput = v3_scale(throughput, 1.0f - sf.alpha);
      }
      if (++layers > K_MAX_LAYERS || v3_max_component(throughput) <= 0.0f) break;
      org = v3_madd(sf.position, dir, k_ray_epsilon(sf.position));
      continue;
    }

    if (params->mode == K_MODE_ALBEDO) { radiance = v3_add(sf.albedo, sf.emission); break; }
    if (params->mode == K_MODE_NORMALS) { radiance = v3_add(v3_scale(sf.normal, 0.5f), v3s(0.5f)); break; }
    if (params->mode == K_MODE_SPECULAR) { radiance = sf.specular; break; }

    KFrameParams vertex_params = *params;
    if (bounce > 0u) {
      /* Path regularisation: after a bounce, a sharp highlight lit by next-event estimation is a
       * caustic path the bounce found by chance (a firefly). Widen it and drop the boost there. */
      sf.roughness = k_fmax(sf.roughness, K_REGULARIZED_ROUGHNESS);
      vertex_params.spec_boost = 1.0f;
    }
    KVec3 contribution = sf.emission;
    contribution = v3_add(contribution, k_direct_lighting(ctx, &vertex_params, &sf, wo, rng));
    contribution = v3_mul(throughput, contribution);
    if (bounce > 0u) contribution = k_clamp_radiance(contribution, params->firefly_clamp);
    radiance = v3_add(radiance, contribution);

    if (params->mode == K_MODE_DIRECT || bounce >= params->max_bounces) break;

    KVec3 wi;
    float u_lobe = k_rng_next(rng), u1 = k_rng_next(rng), u2 = k_rng_next(rng);
    KVec3 weight = k_brdf_sample(&sf, wo, u_lobe, u1, u2, &wi);
    if (v3_max_component(weight) <= 0.0f || v3_dot(wi, sf.geo_normal) <= 0.0f) break;
    throughput = v3_mul(throughput, weight);
    spread += K_BOUNCE_SPREAD;
    ++bounce;
    if ((float)bounce >= params->rr_start) {
      float keep = k_clamp(v3_max_component(throughput), 0.05f, 0.95f);
      if (k_rng_next(rng) >= keep) break;
      throughput = v3_scale(throughput, 1.0f / keep);
    }
    org = v3_madd(sf.position, sf.geo_normal, k_ray_epsilon(sf.position));
    dir = wi;
    layers = 0u;
  }
  return radiance;
}

KFN KVec3 k_render_pixel(KTraceCtx* ctx, const KFrameParams* params, const KCamera* cam, kuint x, kuint y) {
  kuint spp = params->spp > 0u ? params->spp : 1u;
  KVec3 sum = v3s(0.0f);
  KVec3 org = v3_load(cam->origin);
  float pixel_spread = 2.0f * cam->tan_half_fov_x / (float)cam->width;
  for (kuint s = 0u; s < spp; ++s) {
    KRng rng = k_rng_seed(x, y, params->frame_index, s);
    float jx = k_rng_next(&rng), jy = k_rng_next(&rng);
    KVec3 dir = k_camera_direction(cam, (float)x + jx, (float)y + jy);
    sum = v3_add(sum, k_trace_path(ctx, params, org, dir, pixel_spread, &rng));
  }
  return v3_scale(sum, 1.0f / (float)spp);
}

#endif
