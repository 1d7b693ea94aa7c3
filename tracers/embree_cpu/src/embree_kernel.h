// The integrator instantiated for Embree: k_trace_closest / k_trace_occluded on rtcIntersect1 /
// rtcOccluded1, with filter functions applying instance masks and k_hit_transmittance.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>

#include "cohort/kernel/material.h"

namespace cohort::tracers::embree_kernel {

struct TraceCtx {
  KSceneView scene;
  RTCScene top;
  uint64_t rays;  // rays traced through this context, for the benchmarks
};

// Embree hands this back to the filter functions (the RTCIntersectContext must come first).
struct FilterContext {
  RTCIntersectContext base;
  const KSceneView* scene;
  kuint ray_mask;
  int shadow_ray;
};

void filter_hit(const RTCFilterFunctionNArguments* args);

inline FilterContext filter_context(const KSceneView* scene, kuint ray_mask, int shadow_ray) {
  FilterContext fc;
  rtcInitIntersectContext(&fc.base);
  fc.scene = scene;
  fc.ray_mask = ray_mask;
  fc.shadow_ray = shadow_ray;
  return fc;
}

// A ray from org along dir up to tmax, visible to every geometry (masks are applied by filter_hit).
inline RTCRay make_ray(KVec3 org, KVec3 dir, float tmax) {
  RTCRay ray;
  ray.org_x = org.x; ray.org_y = org.y; ray.org_z = org.z;
  ray.dir_x = dir.x; ray.dir_y = dir.y; ray.dir_z = dir.z;
  ray.tnear = 0.0f;
  ray.tfar = tmax;
  ray.mask = 0xFFFFFFFFu;
  ray.time = 0.0f;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

}  // namespace cohort::tracers::embree_kernel

typedef cohort::tracers::embree_kernel::TraceCtx KTraceCtx;

static inline int k_trace_closest(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask, KHit* hit) {
  cohort::tracers::embree_kernel::FilterContext fc = cohort::tracers::embree_kernel::filter_context(&ctx->scene, ray_mask, 0);
  RTCRayHit rh;
  rh.ray = cohort::tracers::embree_kernel::make_ray(org, dir, tmax);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  ++ctx->rays;
  rtcIntersect1(ctx->top, &fc.base, &rh);
  hit->cost = 0u;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 0;
  hit->t = rh.ray.tfar;
  hit->u = rh.hit.u;
  hit->v = rh.hit.v;
  hit->instance = rh.hit.instID[0];
  hit->triangle = ctx->scene.blases[ctx->scene.instances[hit->instance].blas].tri_offset + rh.hit.primID;
  return 1;
}

static inline int k_trace_occluded(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask) {
  cohort::tracers::embree_kernel::FilterContext fc = cohort::tracers::embree_kernel::filter_context(&ctx->scene, ray_mask, 1);
  RTCRay ray = cohort::tracers::embree_kernel::make_ray(org, dir, tmax);
  ++ctx->rays;
  rtcOccluded1(ctx->top, &fc.base, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on occlusion
}

#include "cohort/kernel/integrator.h"
#include "cohort/kernel/aux_outputs.h"
