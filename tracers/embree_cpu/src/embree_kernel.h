// The integrator instantiated for Embree: k_trace_closest / k_trace_occluded on rtcIntersect1 /
// rtcOccluded1, with filter functions applying instance masks and k_hit_transmittance. A path's
// camera ray is not traced here: the tile traced every camera ray ahead in packets
// (embree_tiles.cpp) and primes the context with the hit, which the path's first trace takes.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <vector>

#include "cohort/tracers/embree_texture.h"  // before the kernel headers: K_TEXEL_BILINEAR
#include "cohort/tracers/embree_light_box.h"  // and K_LIGHT_NODE_HOLDS
#include "cohort/kernel/material.h"
#include "cohort/tracers/embree_tracer.h"

namespace cohort::tracers::embree_kernel {

// Every ray the integrator asks for, by class, when a benchmark records them (EmbreeTracer::record_rays).
struct RayLog {
  EmbreeRaySet rays;
  KVec3 camera_dir;  // the current sample's camera direction: closest rays along it are camera rays
};

enum RayClass { kCameraRay, kShadowRay, kBounceRay };

// Appends a ray to the log. Out of line (embree_tracer.cpp): the tile renderer is also compiled for
// x86-64-v3, and no code compiled that way may end up shared with the baseline build (std templates).
void log_ray(RayLog* log, RayClass ray_class, KVec3 org, KVec3 dir, float tmax, kuint ray_mask);

// A BLAS split in two Embree geometries (EmbreeTracer::set_split_filters): its triangles that no ray can pass
// in geometry 0, without a filter function, and those a ray may pass in geometry 1, with it. Per geometry, the
// scene triangle of each primitive; null where a BLAS is one geometry over its triangles in order.
struct SplitBlas {
  const kuint* triangles[2];
};

struct TraceCtx {
  KSceneView scene;
  const SplitBlas* split;  // per BLAS (may be null: no BLAS is split)
  RTCScene top;
  uint64_t rays;  // rays traced through this context, for the benchmarks and the balancer's row work
  // The camera ray's closest hit, traced ahead in a packet: taken by the next k_trace_closest along
  // primed_dir with an infinite tmax (the path's first trace), then cleared.
  const KHit* primed_hit;
  int primed_found;
  KVec3 primed_dir;
  RayLog* log;  // null unless recording
};

// Embree hands this back to the filter functions (the RTCIntersectContext must come first). The filter
// reads each ray's mask from its lane, so that rays of one packet or stream may differ in it (a tile's
// shadow rays: from noSelfShadow surfaces or not).
struct FilterContext {
  RTCIntersectContext base;
  const KSceneView* scene;
  const SplitBlas* split;
  int occlusion;  // shadow rays: material.h's ray kind from each ray's mask (k_shadow_ray_kind); else 0
};

void filter_hit(const RTCFilterFunctionNArguments* args);

// coherent: rays of one batch start close together and point alike (camera packets), so Embree may
// trace them together.
static inline FilterContext filter_context(const KSceneView* scene, const SplitBlas* split, bool occlusion,
                                           bool coherent = false) {
  FilterContext fc;
  rtcInitIntersectContext(&fc.base);
  if (coherent) fc.base.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  fc.scene = scene;
  fc.split = split;
  fc.occlusion = occlusion;
  return fc;
}

// A ray from org along dir up to tmax that sees the instances sharing a bit with ray_mask (Embree's ray
// masks where the device has them, filter_hit otherwise).
static inline RTCRay make_ray(KVec3 org, KVec3 dir, float tmax, kuint ray_mask) {
  RTCRay ray;
  ray.org_x = org.x; ray.org_y = org.y; ray.org_z = org.z;
  ray.dir_x = dir.x; ray.dir_y = dir.y; ray.dir_z = dir.z;
  ray.tnear = 0.0f;
  ray.tfar = tmax;
  ray.mask = ray_mask;
  ray.time = 0.0f;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

// The scene's triangle index of an Embree hit: primID counts within the instance's BLAS, or within one of a
// split BLAS's two geometries.
static inline kuint scene_triangle(const KSceneView& scene, const SplitBlas* split, kuint instance, kuint geometry,
                                   kuint prim) {
  const kuint blas = scene.instances[instance].blas;
  if (split && split[blas].triangles[geometry & 1u]) return split[blas].triangles[geometry & 1u][prim];
  return scene.blases[blas].tri_offset + prim;
}

}  // namespace cohort::tracers::embree_kernel

typedef cohort::tracers::embree_kernel::TraceCtx KTraceCtx;

static inline int k_trace_closest(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask, KHit* hit) {
  namespace ek = cohort::tracers::embree_kernel;
  hit->cost = 0u;
  ++ctx->rays;
  if (ctx->primed_hit && tmax == K_INF && dir.x == ctx->primed_dir.x && dir.y == ctx->primed_dir.y &&
      dir.z == ctx->primed_dir.z) {
    const KHit* primed = ctx->primed_hit;
    ctx->primed_hit = nullptr;
    if (!ctx->primed_found) return 0;
    *hit = *primed;
    return 1;
  }
  if (ctx->log) {
    const bool camera = dir.x == ctx->log->camera_dir.x && dir.y == ctx->log->camera_dir.y &&
                        dir.z == ctx->log->camera_dir.z;
    ek::log_ray(ctx->log, camera ? ek::kCameraRay : ek::kBounceRay, org, dir, tmax, ray_mask);
  }
  ek::FilterContext fc = ek::filter_context(&ctx->scene, ctx->split, false);
  RTCRayHit rh;
  rh.ray = ek::make_ray(org, dir, tmax, ray_mask);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(ctx->top, &fc.base, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 0;
  hit->t = rh.ray.tfar;
  hit->u = rh.hit.u;
  hit->v = rh.hit.v;
  hit->instance = rh.hit.instID[0];
  hit->triangle = ek::scene_triangle(ctx->scene, ctx->split, hit->instance, rh.hit.geomID, rh.hit.primID);
  return 1;
}

static inline int k_trace_occluded(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask) {
  namespace ek = cohort::tracers::embree_kernel;
  ++ctx->rays;
  if (ctx->log) ek::log_ray(ctx->log, ek::kShadowRay, org, dir, tmax, ray_mask);
  ek::FilterContext fc = ek::filter_context(&ctx->scene, ctx->split, true);
  RTCRay ray = ek::make_ray(org, dir, tmax, ray_mask);
  rtcOccluded1(ctx->top, &fc.base, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on occlusion
}
