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
#include "emissive_tree.h"
#include "emitters.h"
#include "fog.h"
#include "path_state.h"
#include "light_gather.h"
#include "lit_vertex.h"
#include "shadow_queue.h"
#include "light_tree.h"
#include "rng.h"
#include "path_pattern.h"
#include "environment.h"

#ifndef K_CTX_SCENE
#define K_CTX_SCENE(ctx) (&(ctx)->scene)
#endif

/* Which builds compile K_LIGHTS_DENSE's pick (light_tree.h's k_light_dense_pick): 1 (the default), beside
 * the other ways, chosen at run time (Embree, OpenCL); 0, not at all (CUDA's kernels for the other ways, so
 * that their code and registers stay what they are without it: a frame asking for it is given `all`'s pick
 * there); 2, the only way compiled (CUDA's dense kernels, render_band_dense.cu, launched only for frames with
 * K_LIGHTS_DENSE and light_samples > 0). Why CUDA builds it apart: docs/integrator.md, "Dense rooms". */
#ifndef K_LIGHTS_DENSE_BUILD
#define K_LIGHTS_DENSE_BUILD 1
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

/* Russian roulette on a shadow ray (KFrameParams.shadow_rr, 0: off). A light sample whose unshadowed
 * contribution to the pixel (its value times the path's throughput) is below the threshold traces its
 * shadow ray with probability value / threshold and counts threshold / value times when it does: the
 * estimate stays unbiased, the added variance is at most threshold x value, and most rays toward far or
 * faint lights (a sky shaft's cap seen from rooms away, the tail of a light's falloff) are never traced.
 * Returns the factor to scale the sample by, 0 when its ray is skipped. */
KFN float k_shadow_roulette(float threshold, float pixel_value, KRng* rng) {
  if (!(threshold > 0.0f) || pixel_value >= threshold) return 1.0f;
  if (!(pixel_value > 0.0f)) return 0.0f;
  float keep = pixel_value / threshold;
  return k_rng_next(rng) < keep ? 1.0f / keep : 0.0f;
}

/* The shadow ray toward a point jittered over the light's extent, into *ray (its value left to the caller);
 * 0 when the light cannot be seen from the point (it lies behind the surface). */
KFN int k_light_shadow_ray(const KFrameParams* params, const KSurface* sf, KGLOBAL const KLight* light, float u1,
                           float u2, KShadowRay* ray) {
  ray->tmax = 0.0f;
  ray->mask = 0u;
  if (light->flags & K_LIGHT_NO_SHADOWS) return 1;
  float dist;
  KVec3 dir = k_light_jittered_direction(light, sf->position, params->soft_shadow_scale, u1, u2, &dist);
  if (v3_dot(dir, sf->geo_normal) <= 0.0f) return 0;
  float eps = k_ray_epsilon(sf->position);
  ray->org = v3_madd(sf->position, sf->geo_normal, eps);
  ray->dir = dir;
  ray->tmax = dist < K_INF ? dist - 2.0f * eps : K_INF;
  ray->mask = k_shadow_ray_mask(sf->flags);
  return 1;
}

/* One light sample as K_LIGHTS_EVERY takes each light: `value` (its unshadowed contribution, over its
 * probability of being sampled) queued behind its shadow ray when the shadow roulette keeps it. Every
 * light sample draws its random numbers in this order. */
KFN void k_light_sample_emit(KTraceCtx* ctx, const KFrameParams* params, const KSurface* sf,
                             KGLOBAL const KLight* light, KVec3 value, float path_weight, KRng* rng,
                             KShadowQueue* queue, KVertexLight* vertex) {
  float u1 = k_rng_next(rng), u2 = k_rng_next(rng);
  float kept = k_shadow_roulette(params->shadow_rr, v3_max_component(value) * path_weight, rng);
  KShadowRay ray;
  if (kept > 0.0f && k_light_shadow_ray(params, sf, light, u1, u2, &ray)) {
    ray.value = v3_scale(value, kept);
    ray.kept = 1.0f;
    k_shadow_queue_push(ctx, queue, vertex, ray);
  }
}

/* Whether k_direct_lighting traces each light it takes once (`every`, gather) rather than light_samples
 * samples of one light each, which it averages. */
KFN int k_lights_one_ray_each(const KFrameParams* params) {
  return (params->light_sampling == K_LIGHTS_GATHER && params->light_samples > 0u) || params->light_samples == 0u ||
         params->light_sampling == K_LIGHTS_EVERY;
}

/* Next-event estimation toward the Doom 3 lights, six ways (KFrameParams.light_sampling):
 * - K_LIGHTS_EVERY (or light_samples == 0): every light that reaches the point, one shadow ray each
 *   (as Doom 3 draws every interaction; lowest noise where few lights overlap, cost grows with them).
 * - K_LIGHTS_TREE (default): per light sample, one light picked through the light tree among those
 *   whose volume holds the point (light_tree.h has the pdf), one shadow ray toward it.
 * - K_LIGHTS_IN_RANGE: the same without the tree's descent: one light per sample picked in proportion to
 *   its unshadowed contribution among every light whose volume holds the point (cost grows with those, not
 *   with the map's lights).
 * - K_LIGHTS_DENSE: per light sample, a descent of the tree by a guess of each subtree's contribution to at
 *   most K_LIGHT_DENSE_LEAF lights, then in-range's pick among them (light_tree.h): bounded work where many
 *   lights reach a point (K_LIGHTS_DENSE_BUILD says which builds compile it).
 * - K_LIGHTS_ALL: per light sample, one light picked over every light of the map in proportion to its
 *   unshadowed contribution (the reference for the tree: same pick, cost grows with the map).
 * - K_LIGHTS_GATHER: `every` among the lights whose volume holds the point, found through the tree, while
 *   there are at most light_samples of them; beyond that at most light_samples shadow rays, each light
 *   with a known probability (light_gather.h).
 * Each sample's shadow ray goes to the queue with its value (shadow_queue.h), which adds the values of the
 * visible ones, in order, to the vertex's direct sum. */
KFN void k_direct_lighting(KTraceCtx* ctx, const KFrameParams* params, const KSurface* sf, KVec3 wo, float path_weight,
                           KRng* rng, KShadowQueue* queue, KVertexLight* vertex) {
  const KSceneView* scene = K_CTX_SCENE(ctx);
#if K_LIGHTS_DENSE_BUILD != 2
  int gather = params->light_sampling == K_LIGHTS_GATHER && params->light_samples > 0u;
  if (k_lights_one_ray_each(params)) {
    /* `every` walks the whole light array; gather, the lights k_light_gather chose (outlined, on values,
     * so that the kernel's other paths keep ctx and sf in registers). One loop traces both. */
    KLightGather gathered;
    gathered.count = scene->light_count;
    if (gather) {
      gathered = k_light_gather(*scene, *sf, wo, params->spec_boost, params->light_samples, *rng);
      *rng = gathered.rng;
    }
    for (kuint k = 0u; k < gathered.count; ++k) {
      kuint i = gather ? gathered.light[k] : k;
      KGLOBAL const KLight* light = &scene->lights[i];
      KVec3 c = gather ? gathered.value[k] : k_light_unshadowed(scene, light, sf, wo, params->spec_boost);
      if (v3_max_component(c) <= 0.0f) continue;
      k_light_sample_emit(ctx, params, sf, light, c, path_weight, rng, queue, vertex);
    }
    return;
  }
#endif
  kuint samples = params->light_samples;
  for (kuint k = 0u; k < samples; ++k) {
    kuint chosen = K_NONE;
    KVec3 chosen_contrib = v3s(0.0f);
    float pdf = 0.0f;
    float u_pick = k_rng_next(rng);
#if K_LIGHTS_DENSE_BUILD == 2
    chosen = k_light_dense_pick(scene, sf, wo, params->spec_boost, k_rng_next(rng), u_pick, &chosen_contrib, &pdf);
#else
    if (params->light_sampling == K_LIGHTS_TREE || params->light_sampling == K_LIGHTS_IN_RANGE) {
      float u_descend = k_rng_next(rng);
      kuint descend_above = params->light_sampling == K_LIGHTS_TREE ? K_LIGHT_TREE_GATHER : K_NONE;
      chosen = k_light_tree_pick(scene, sf, wo, params->spec_boost, descend_above, 0, u_descend, u_pick,
                                 &chosen_contrib, &pdf);
    }
#if K_LIGHTS_DENSE_BUILD == 1
    else if (params->light_sampling == K_LIGHTS_DENSE) {
      float u_descend = k_rng_next(rng);
      chosen = k_light_dense_pick(scene, sf, wo, params->spec_boost, u_descend, u_pick, &chosen_contrib, &pdf);
    }
#endif
    else {
      float total = 0.0f, chosen_weight = 0.0f;
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
      pdf = chosen != K_NONE ? chosen_weight / total : 0.0f;
    }
#endif
    float u1 = k_rng_next(rng), u2 = k_rng_next(rng);
    if (chosen == K_NONE || !(pdf > 0.0f)) continue;
    KVec3 value = v3_scale(chosen_contrib, 1.0f / pdf);
    float kept = k_shadow_roulette(params->shadow_rr, v3_max_component(value) * path_weight / (float)samples, rng);
    KShadowRay ray;
    if (kept <= 0.0f || !k_light_shadow_ray(params, sf, &scene->lights[chosen], u1, u2, &ray)) continue;
    ray.value = value;
    ray.kept = kept;
    k_shadow_queue_push(ctx, queue, vertex, ray);
  }
}

/* Power-heuristic weight (exponent 2) of a sample drawn with pdf `own` against the other strategy's pdf. */
KFN float k_power_heuristic(float own, float other) {
  float a = own * own, b = other * other;
  return a + b > 0.0f ? a / (a + b) : 0.0f;
}

/* The density per solid angle with which emissive-triangle sampling (k_emissive_lighting) from the point
 * p proposes a point of this triangle seen dist2 away at cosine cos_light on the emitter: the tree's pick
 * probability at p times 1 / area, converted to solid angle. It is the same formula on both sides of the
 * MIS, so the two weights of a path sum to one. */
KFN float k_emissive_pdf(const KSceneView* scene, KVec3 p, kuint instance, kuint triangle, float dist2, float cos_light) {
  if (scene->emissive_count == 0u || !(cos_light > 0.0f)) return 0.0f;
  kuint index = k_emissive_find(scene, instance, triangle);
  if (index == K_NONE) return 0.0f;
  KGLOBAL const KEmissiveTriangle* e = &scene->emissive[index];
  float double_area = k_triangle_double_area(v3_load_g(e->p0), v3_load_g(e->p1), v3_load_g(e->p2));
  if (!(double_area > 0.0f)) return 0.0f;
  return k_emissive_tree_pdf(scene, p, index) * 2.0f / double_area * dist2 / cos_light;
}

/* One emissive-triangle sample for next-event estimation: a triangle picked through the emissive tree
 * (near and bright ones first), a uniform point on it, its emission there, one shadow ray (to the queue,
 * which sets the vertex's emissive term when the point is visible). With a bounce to follow from this
 * vertex the value is weighted by the power heuristic against BRDF sampling, which weighs the emission it
 * finds the same way (k_path_hit_lit); without one it stands alone (weight 1). picked: the pick made
 * ahead for this sample's first random number, or null to pick here. */
KFN void k_emissive_lighting(KTraceCtx* ctx, const KSurface* sf, KVec3 wo, int bounce_follows, float shadow_rr,
                             float path_weight, KRng* rng, const KEmissivePick* picked, KShadowQueue* queue,
                             KVertexLight* vertex) {
  const KSceneView* scene = K_CTX_SCENE(ctx);
  float u_pick = k_rng_next(rng), u1 = k_rng_next(rng), u2 = k_rng_next(rng);
  float pick = 0.0f;
  kuint index;
  if (picked) {
    index = picked->index;
    pick = picked->prob;
  } else {
    index = k_emissive_tree_pick(scene, sf->position, u_pick, &pick);
  }
  if (index == K_NONE || !(pick > 0.0f)) return;
  KGLOBAL const KEmissiveTriangle* e = &scene->emissive[index];

  float su = k_sqrt(u1);
  float bu = su * (1.0f - u2), bv = su * u2;   /* barycentrics of p1 and p2 */
  KVec3 p0 = v3_load_g(e->p0), p1 = v3_load_g(e->p1), p2 = v3_load_g(e->p2);
  KVec3 x = v3_add(v3_scale(p0, 1.0f - bu - bv), v3_add(v3_scale(p1, bu), v3_scale(p2, bv)));
  KVec3 cr = v3_cross(v3_sub(p1, p0), v3_sub(p2, p0));
  float double_area = v3_length(cr);
  if (!(double_area > 0.0f)) return;
  KVec3 to_light = v3_sub(x, sf->position);
  float dist2 = v3_dot(to_light, to_light);
  if (!(dist2 > 0.0f)) return;
  float dist = k_sqrt(dist2);
  KVec3 wi = v3_scale(to_light, 1.0f / dist);
  float cos_light = k_fabs(v3_dot(cr, wi)) / double_area;   /* emitters shine from both faces */
  if (cos_light <= 1e-6f) return;
  KVec3 f = k_brdf_eval_cos(sf, wo, wi, 1.0f);
  if (v3_max_component(f) <= 0.0f) return;

  KGLOBAL const KMaterial* m = &scene->materials[k_hit_material(scene, e->instance, e->triangle)];
  KVec3 le = v3(m->emissive_color[0], m->emissive_color[1], m->emissive_color[2]);
  if (m->emissive_tex != K_NONE) {
    float s, t;
    k_hit_st(scene, e->triangle, bu, bv, m, &s, &t);
    le = v3_mul(le, v4_rgb(k_texture_sample(scene, m->emissive_tex, s, t)));
  }
  le = v3_mul(le, v4_rgb(k_hit_vertex_color(scene, e->triangle, bu, bv, m->flags)));
  if (v3_max_component(le) <= 0.0f) return;

  float pdf = pick * 2.0f / double_area * dist2 / cos_light;
  float weight = 1.0f;
  if (bounce_follows)
    weight = k_power_heuristic(pdf, k_brdf_pdf(sf, wo, wi));
  KVec3 value = v3_scale(v3_mul(le, f), weight / pdf);
  float kept = k_shadow_roulette(shadow_rr, v3_max_component(value) * path_weight, rng);
  if (kept <= 0.0f) return;

  float eps = k_ray_epsilon(sf->position);
  KShadowRay ray;
  ray.org = v3_madd(sf->position, sf->geo_normal, eps);
  KVec3 seg = v3_sub(x, ray.org);
  float seg_len = v3_length(seg);
  ray.dir = v3_scale(seg, 1.0f / seg_len);
  ray.tmax = seg_len - 2.0f * k_ray_epsilon(x);
  if (!(ray.tmax > 0.0f)) ray.tmax = 0.0f;   /* no room for an occluder (NaN included): visible */
  ray.mask = k_shadow_ray_mask(sf->flags) | K_SHADOW_RAY_EMISSIVE;
  ray.value = v3_scale(value, kept);
  ray.kept = 1.0f;
  k_shadow_queue_push(ctx, queue, vertex, ray);
}

KFN KVec3 k_clamp_radiance(KVec3 c, float limit) {
  if (limit <= 0.0f) return c;
  float m = v3_max_component(c);
  return m > limit ? v3_scale(c, limit / m) : c;
}

/* What an opaque vertex adds to its path's radiance once its shadow rays are in:
 * throughput * (emission + environment + direct + emissive), clamped after a bounce, in that order of
 * additions whether the rays were walked as they came or by a wavefront's shadow kernel. */
KFN KVec3 k_vertex_light_sum(const KVertexLight* v) {
  KVec3 direct = v->direct_scale > 0.0f ? v3_scale(v->direct, v->direct_scale) : v->direct;
  KVec3 c = v3_add(v->base, direct);
  if (v->has_emissive) c = v3_add(c, v->emissive);
  return k_clamp_radiance(v3_mul(v->throughput, c), v->clamp);
}

KFN KVec3 k_heat_color(float x) {
  x = k_saturate(x);
  return v3(k_saturate(2.0f * x - 1.0f), 1.0f - k_fabs(2.0f * x - 1.0f), k_saturate(1.0f - 2.0f * x));
}

KFN KVec3 k_id_color(kuint id) {
  kuint h = k_pcg_hash(id);
  return v3((float)(h & 0xFFu) / 255.0f, (float)((h >> 8) & 0xFFu) / 255.0f, (float)((h >> 16) & 0xFFu) / 255.0f);
}

/* Which surface a camera ray met first, for the aux planes (K_AUX_PATH_FIRST_HIT). */
KFN void k_record_first_hit(KGLOBAL KPathFirstHit* record, kuint instance, kuint triangle, kuint sky) {
  record->instance = instance;
  record->triangle = triangle;
  record->sky = sky;
  record->pad = 0u;
}

/* A camera ray's path before its first trace; pixel_spread is the angle one pixel subtends (for mip
 * selection), rng the sample's stream after the camera's jitter. */
KFN void k_path_begin(KPathState* s, KVec3 org, KVec3 dir, float pixel_spread, KRng rng) {
  s->radiance = v3s(0.0f);
  s->throughput = v3s(1.0f);
  s->org = org;
  s->dir = dir;
  s->vertex_position = org;
  s->cone_width = 0.0f;
  s->spread = pixel_spread;
  s->vertex_brdf_pdf = 0.0f;
  s->bounce = 0u;
  s->layers = 0u;
  s->rng = rng;
  s->pad = 0u;
}

/* The path's ray met nothing (hit->cost: the steps the walk took, for the BVH view): the path ends. */
KFN void k_path_miss(const KSceneView* scene, const KFrameParams* params, KPathState* s, const KHit* hit) {
  int lit_mode = params->mode == K_MODE_PATH || params->mode == K_MODE_DIRECT;
  if (params->mode == K_MODE_BVH && s->bounce == 0u) s->radiance = k_heat_color((float)hit->cost / 200.0f);
  if (lit_mode) k_apply_fog(scene, s->org, s->dir, K_INF, &s->radiance, &s->throughput);
}

/* The opaque vertex's shading after its Doom 3 lights (the locals of k_path_hit_lit, KLitVertex's fields): its
 * emissive sample (picked here, or ahead: picked, may be null), its light, its bounce. 1 when the path goes on
 * with its bounce ray in s->org and s->dir (s->bounce one more); 0 when it ends. */
KFN int k_path_vertex_shade(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, const KSurface* sf,
                            KVec3 wo, KVec3 contribution, float path_weight, KRng rng, int emissive_nee,
                            const KEmissivePick* picked, KShadowQueue* shadows, KVertexLight* vertex) {
  if (emissive_nee) {
    int bounce_follows = params->mode != K_MODE_DIRECT && s->bounce < params->max_bounces;
    k_emissive_lighting(ctx, sf, wo, bounce_follows, params->shadow_rr, path_weight, &rng, picked, shadows,
                        vertex);
  }
  vertex->throughput = s->throughput;
  vertex->clamp = s->bounce > 0u ? params->firefly_clamp : 0.0f;
  vertex->base = contribution;
  vertex->direct_scale = k_lights_one_ray_each(params) ? 0.0f : 1.0f / (float)params->light_samples;
  vertex->has_emissive = (kuint)emissive_nee;
  if (shadows->count == 0u) s->radiance = v3_add(s->radiance, k_vertex_light_sum(vertex));

  if (params->mode == K_MODE_DIRECT || s->bounce >= params->max_bounces) { s->rng = rng; return 0; }

  KVec3 wi;
  float u_lobe = k_rng_next(&rng), u1 = k_rng_next(&rng), u2 = k_rng_next(&rng);
  KVec3 weight = k_brdf_sample(sf, wo, u_lobe, u1, u2, &wi);
  if (v3_max_component(weight) <= 0.0f || v3_dot(wi, sf->geo_normal) <= 0.0f) { s->rng = rng; return 0; }
  s->throughput = v3_mul(s->throughput, weight);
  s->vertex_position = sf->position;
  s->vertex_brdf_pdf = k_brdf_pdf(sf, wo, wi);
  s->spread += K_BOUNCE_SPREAD;
  ++s->bounce;
  if ((float)s->bounce >= params->rr_start) {
    float keep = k_clamp(v3_max_component(s->throughput), 0.05f, 0.95f);
    if (k_rng_next(&rng) >= keep) { s->rng = rng; return 0; }
    s->throughput = v3_scale(s->throughput, 1.0f / keep);
  }
  s->rng = rng;
  s->org = v3_madd(sf->position, sf->geo_normal, k_ray_epsilon(sf->position));
  s->dir = wi;
  s->layers = 0u;
  return 1;
}

/* The opaque vertex's shading after its Doom 3 lights, from what k_path_hit_lit left in *lit (the emissive
 * pick made ahead: picked, may be null). 1 when the path goes on with its bounce ray in s->org and s->dir
 * (s->bounce one more); 0 when it ends. */
KFN int k_path_vertex_end(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, const KLitVertex* lit,
                          const KEmissivePick* picked, KShadowQueue* shadows, KVertexLight* vertex) {
  return k_path_vertex_shade(ctx, params, s, &lit->sf, lit->wo, lit->contribution, lit->path_weight, lit->rng,
                             lit->emissive_nee, picked, shadows, vertex);
}

/* The path's ray (s->org, s->dir) met `hit`: shades it. 1 when the path goes on, with its next ray in s->org
 * and s->dir (through a transparent layer, s->bounce unchanged, or a bounce, s->bounce one more); 0 when it
 * ends. With lit (may be null), an opaque vertex of a lit mode stops after its Doom 3 lights instead:
 * K_PATH_VERTEX_LIT, its shading to be ended by k_path_vertex_end from *lit (and a transparent layer's 1 is
 * never a bounce). first_hit (may be null): where the ray's first opaque surface is recorded for the aux
 * planes (recorded before the first bounce only). shadows (empty on entry): where an opaque vertex's shadow
 * rays go; when some are left in its slots (shadows->count > 0) the vertex's light waits in *vertex, for the
 * caller to add k_vertex_light_sum to s->radiance once they are walked, before the path's next segment;
 * otherwise it is in s->radiance already. */
KFN int k_path_hit_lit(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, KHit hit,
                       KGLOBAL KPathFirstHit* first_hit, KShadowQueue* shadows, KVertexLight* vertex,
                       KLitVertex* lit) {
  const KSceneView* scene = K_CTX_SCENE(ctx);
  int emissive_nee = params->emissive_samples > 0u && scene->emissive_count > 0u;
  KVec3 org = s->org, dir = s->dir;
  int lit_mode = params->mode == K_MODE_PATH || params->mode == K_MODE_DIRECT;
  if (first_hit && s->bounce != 0u) first_hit = 0;
  if (params->mode == K_MODE_BVH) { s->radiance = k_heat_color((float)hit.cost / 200.0f); return 0; }
  if (params->mode == K_MODE_TRIANGLES) { s->radiance = k_id_color(hit.triangle); return 0; }
  if (lit_mode) {
    k_apply_fog(scene, org, dir, hit.t, &s->radiance, &s->throughput);
    if (v3_max_component(s->throughput) <= 0.0f) return 0;
  }
  kuint hit_material = k_hit_material(scene, hit.instance, hit.triangle);
  if (scene->materials[hit_material].blend == K_BLEND_SKY) {
    /* The sky: what its cube shows along the ray, and nothing behind it. */
    if (first_hit) k_record_first_hit(first_hit, hit.instance, hit.triangle, 1u);
    if (lit_mode || params->mode == K_MODE_ALBEDO) {
      KVec3 sky = v3_mul(s->throughput, k_sky_radiance(scene, hit.instance, hit_material, dir));
      s->radiance = v3_add(s->radiance, s->bounce > 0u ? k_clamp_radiance(sky, params->firefly_clamp) : sky);
    }
    return 0;
  }
  s->cone_width += s->spread * hit.t;
  KSurface sf = k_surface_eval(scene, hit, org, dir, s->cone_width);
  KVec3 wo = v3_neg(dir);

  if (sf.blend != K_BLEND_OPAQUE) {
    /* Transparent layers: shade the layer, carry on through it without consuming a bounce. An
     * environment stage (glass) adds its reflection over what the layer does, or, drawn before the
     * layer's stage, under it: filtered by the layer like what is behind. */
    KVec3 env = lit_mode ? k_environment_radiance(scene, hit, hit_material, sf.normal, dir) : v3s(0.0f);
    KVec3 env_throughput = s->throughput;
    if (sf.blend == K_BLEND_ADDITIVE) {
      s->radiance = v3_add(s->radiance, v3_mul(s->throughput, v3_add(sf.albedo, sf.emission)));
    } else if (sf.blend == K_BLEND_MODULATE) {
      s->throughput = v3_mul(s->throughput, sf.albedo);
    } else {
      s->radiance = v3_add(s->radiance, v3_scale(v3_mul(s->throughput, sf.albedo), sf.alpha));
      s->throughput = v3_scale(s->throughput, 1.0f - sf.alpha);
    }
    env = v3_mul((sf.flags & K_MAT_ENV_UNDER_LAYER) ? s->throughput : env_throughput, env);
    s->radiance = v3_add(s->radiance, s->bounce > 0u ? k_clamp_radiance(env, params->firefly_clamp) : env);
    if (++s->layers > K_MAX_LAYERS || v3_max_component(s->throughput) <= 0.0f) return 0;
    s->org = v3_madd(sf.position, dir, k_ray_epsilon(sf.position));
    return 1;
  }

  if (first_hit) k_record_first_hit(first_hit, hit.instance, hit.triangle, 0u);
  if (params->mode == K_MODE_ALBEDO) { s->radiance = v3_add(sf.albedo, sf.emission); return 0; }
  if (params->mode == K_MODE_NORMALS) { s->radiance = v3_add(v3_scale(sf.normal, 0.5f), v3s(0.5f)); return 0; }
  if (params->mode == K_MODE_SPECULAR) { s->radiance = sf.specular; return 0; }

  KFrameParams vertex_params = *params;
  if (s->bounce > 0u) {
    /* Path regularisation: after a bounce, a sharp highlight lit by next-event estimation is a
     * caustic path the bounce found by chance (a firefly). Widen it and drop the boost there. */
    sf.roughness = k_fmax(sf.roughness, K_REGULARIZED_ROUGHNESS);
    vertex_params.spec_boost = 1.0f;
  }
  k_apply_blend_lights(scene, sf.position, &s->radiance, &s->throughput);
  KVec3 contribution = sf.emission;
  if (s->bounce > 0u && emissive_nee && v3_max_component(sf.emission) > 0.0f) {
    KVec3 d = v3_sub(sf.position, s->vertex_position);
    float light_pdf = k_emissive_pdf(scene, s->vertex_position, hit.instance, hit.triangle, v3_dot(d, d),
                                     k_fabs(v3_dot(sf.geo_normal, dir)));
    contribution = v3_scale(contribution, k_power_heuristic(s->vertex_brdf_pdf, light_pdf));
  }
  contribution = v3_add(contribution, k_environment_radiance(scene, hit, hit_material, sf.normal, dir));
  /* The vertex's sums are filled in as its shadow rays come back (now, or after a wavefront's shadow
   * kernel); the rest of it is written after the samples, so as not to be carried through their walks. */
  vertex->direct = v3s(0.0f);
  vertex->emissive = v3s(0.0f);
  vertex->ray_count = 0u;
  float path_weight = v3_max_component(s->throughput);
  KRng rng = s->rng;
  k_direct_lighting(ctx, &vertex_params, &sf, wo, path_weight, &rng, shadows, vertex);
  if (!lit) return k_path_vertex_shade(ctx, params, s, &sf, wo, contribution, path_weight, rng, emissive_nee, 0,
                                      shadows, vertex);
  lit->sf = sf;
  lit->wo = wo;
  lit->contribution = contribution;
  lit->rng = rng;
  lit->path_weight = path_weight;
  lit->emissive_nee = emissive_nee;
  return K_PATH_VERTEX_LIT;
}

/* k_path_hit_lit with the vertex shaded to its end: the GPU kernels' form, compiled as the one function it was
 * before the split (the halves called in sequence spilled more, ptxas sm_90). */
KFN int k_path_hit_queued(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, KHit hit,
                          KGLOBAL KPathFirstHit* first_hit, KShadowQueue* shadows, KVertexLight* vertex) {
  return k_path_hit_lit(ctx, params, s, hit, first_hit, shadows, vertex, 0);
}

#include "path_segment.h"

/* Radiance along one camera ray; pixel_spread is the angle one pixel subtends (for mip selection).
 * first_hit (may be null): where the ray's first opaque surface is recorded for the aux planes (a miss,
 * or a ray the path gives up on before one, is recorded as a miss). The path runs segment after segment,
 * each vertex's shadow rays walked as they come. */
KFN KVec3 k_trace_path(KTraceCtx* ctx, const KFrameParams* params, KVec3 org, KVec3 dir, float pixel_spread,
                       KRng* rng, KGLOBAL KPathFirstHit* first_hit) {
  if (first_hit) k_record_first_hit(first_hit, K_NONE, 0u, 0u);
  KPathState s;
  k_path_begin(&s, org, dir, pixel_spread, *rng);
  KShadowQueue shadows = k_shadow_queue_inline();
  KVertexLight vertex;
  while (k_path_segment(ctx, params, &s, 0, first_hit, &shadows, &vertex)) {
  }
  *rng = s.rng;
  return s.radiance;
}

/* The angle one pixel subtends, for k_trace_path's mip selection. */
KFN float k_pixel_spread(const KCamera* cam) { return 2.0f * cam->tan_half_fov_x / (float)cam->width; }

/* Where sample s of pixel (x, y) leaves the image (its jittered position, in pixels) and, in *rng, the
 * sample's random stream after the jitter. */
KFN void k_camera_sample_position(const KFrameParams* params, kuint x, kuint y, kuint s, KRng* rng, float* sx,
                                  float* sy) {
  *rng = k_rng_seed(x, y, params->frame_index, s);
  float jx = k_rng_next(rng), jy = k_rng_next(rng);
  *sx = (float)x + jx;
  *sy = (float)y + jy;
}

/* Sample s of pixel (x, y): the camera ray's direction (from cam->origin) and, in *rng, the sample's
 * random stream after the jitter, ready for k_trace_path. Tracers that trace camera rays ahead in
 * batches (Embree's packets) start each path from here, so their rays are exactly these. */
KFN KVec3 k_camera_sample(const KFrameParams* params, const KCamera* cam, kuint x, kuint y, kuint s, KRng* rng) {
  float sx, sy;
  k_camera_sample_position(params, x, y, s, rng, &sx, &sy);
  return k_camera_direction(cam, sx, sy);
}

/* A pixel's colour, its paths traced whatever the sparse path pattern says (k_render_pixel asks it);
 * first_hit (may be null): the first sample's first surface, for the aux planes. */
KFN KVec3 k_render_pixel_paths(KTraceCtx* ctx, const KFrameParams* params, const KCamera* cam, kuint x, kuint y,
                               KGLOBAL KPathFirstHit* first_hit) {
  kuint spp = k_paths_per_pixel(params->spp);
  KVec3 sum = v3s(0.0f);
  KVec3 org = v3_load(cam->origin);
  float pixel_spread = k_pixel_spread(cam);
  for (kuint s = 0u; s < spp; ++s) {
    KRng rng;
    KVec3 dir = k_camera_sample(params, cam, x, y, s, &rng);
    sum = v3_add(sum, k_trace_path(ctx, params, org, dir, pixel_spread, &rng, s == 0u ? first_hit : 0));
  }
  return v3_scale(sum, 1.0f / (float)spp);
}

/* A pixel's colour; black, at no cost, where the sparse path pattern (path_pattern.h) leaves it out. */
KFN KVec3 k_render_pixel(KTraceCtx* ctx, const KFrameParams* params, const KCamera* cam, kuint x, kuint y) {
  if (!k_pixel_traces_path(params->path_pixels, params->path_phase, x, y)) return v3s(0.0f);
  return k_render_pixel_paths(ctx, params, cam, x, y, 0);
}

#endif
