// What both tile renderers (embree_tiles.cpp's path per pixel, embree_wave_tile.cpp's wavefront) do alike:
// camera rays in coherent packets, and the aux planes. Static functions: each file is built twice (baseline
// and x86-64-v3) and must keep its own copy of everything it inlines.
#pragma once

#include "embree_kernel.h"  // before the kernel headers: KTraceCtx

#include "cohort/kernel/integrator.h"
#include "cohort/kernel/aux_outputs.h"
#include "cohort/tracers/embree_emissive_picks.h"
#include "embree_tiles.h"

namespace cohort::tracers::embree_tiles {

// The halves of k_path_segment (kernel/path_segment.h), each a function of its own, the same in both renderers:
// inlined into each, the compiler contracted a few different multiply-adds into FMAs (x86-64-v3), so their
// images differed in the last bits. noipa: no copy specialised for one caller's constant arguments either.
__attribute__((noinline, noipa)) static int path_segment_lit(KTraceCtx* ctx, const KFrameParams* params,
                                                             KPathState* s, const KHit* traced,
                                                             KPathFirstHit* first_hit, KShadowQueue* shadows,
                                                             KVertexLight* vertex, KLitVertex* lit) {
  return k_path_segment_lit(ctx, params, s, traced, first_hit, shadows, vertex, lit);
}

__attribute__((noinline, noipa)) static int path_vertex_end(KTraceCtx* ctx, const KFrameParams* params,
                                                            KPathState* s, const KLitVertex* lit,
                                                            const KEmissivePick* picked, KShadowQueue* shadows,
                                                            KVertexLight* vertex) {
  return k_path_vertex_end(ctx, params, s, lit, picked, shadows, vertex);
}

// The number the vertex's emissive sample picks its triangle with: the first it draws (k_emissive_lighting).
static float emissive_pick_number(const KLitVertex& lit) {
  KRng rng = lit.rng;
  return k_rng_next(&rng);
}

// The emissive picks of n lit vertices (embree_emissive_picks.h), the same code in both renderers.
__attribute__((noinline, noipa)) static void emissive_picks(const KSceneView* scene, int n, const KVec3* points,
                                                            const float* us, KEmissivePick* out) {
  embree_emissive::picks(scene, n, points, us, out);
}

// Closest hits of the tile's n camera rays (all from org), 8 to a packet, with a coherent context.
static void trace_camera_packets(embree_kernel::TraceCtx& ctx, KVec3 org, int n, Arena& a) {
  embree_kernel::FilterContext fc = embree_kernel::filter_context(&ctx.scene, ctx.split, false, true);
  for (int first = 0; first < n; first += kPacketSize) {
    RTCRayHit8& rh = a.packets[first / kPacketSize];
    alignas(32) int valid[kPacketSize];  // Embree loads the mask as one vector: unaligned, it faults on AVX-512 CPUs
    for (int k = 0; k < kPacketSize; ++k) {
      const int i = first + k < n ? first + k : n - 1;  // unused lanes repeat the last ray, masked off
      valid[k] = first + k < n ? -1 : 0;
      rh.ray.org_x[k] = org.x; rh.ray.org_y[k] = org.y; rh.ray.org_z[k] = org.z;
      rh.ray.dir_x[k] = a.dirs[i].x; rh.ray.dir_y[k] = a.dirs[i].y; rh.ray.dir_z[k] = a.dirs[i].z;
      rh.ray.tnear[k] = 0.0f;
      rh.ray.tfar[k] = K_INF;
      rh.ray.mask[k] = K_RAY_PRIMARY;
      rh.ray.time[k] = 0.0f;
      rh.ray.id[k] = static_cast<unsigned>(k);
      rh.ray.flags[k] = 0u;
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, ctx.top, &fc.base, &rh);
    for (int k = 0; k < kPacketSize && first + k < n; ++k) {
      const int i = first + k;
      a.found[i] = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
      if (!a.found[i]) continue;
      KHit& hit = a.hits[i];
      hit.t = rh.ray.tfar[k];
      hit.u = rh.hit.u[k];
      hit.v = rh.hit.v[k];
      hit.instance = rh.hit.instID[0][k];
      hit.triangle =
          embree_kernel::scene_triangle(ctx.scene, ctx.split, hit.instance, rh.hit.geomID[k], rh.hit.primID[k]);
      hit.cost = 0u;
      hit.pad0 = hit.pad1 = 0u;
    }
  }
  if (ctx.log)
    for (int i = 0; i < n; ++i) embree_kernel::log_ray(ctx.log, embree_kernel::kCameraRay, org, a.dirs[i], K_INF, K_RAY_PRIMARY);
}

// The tile's aux planes (depth, normal, albedo, id, motion): from the paths' first hits where the frame
// asks for that (k_aux_from_paths), else one unjittered ray through each pixel's centre, traced ahead in
// packets like the camera rays, then k_pixel_aux from those hits.
static void write_aux(const Frame& frame, const Tile& tile, Arena& a, embree_kernel::TraceCtx& ctx, uint64_t* row_rays) {
  const int w = tile.x1 - tile.x0, n = w * (tile.y1 - tile.y0);
  if (k_aux_from_paths(&frame.params)) {
    for (int y = tile.y0; y < tile.y1; ++y) {
      for (int x = 0; x < w; ++x)
        k_aux_from_first_hit(&ctx.scene, &frame.params, &frame.camera, &frame.previous_camera, &frame.history,
                             static_cast<kuint>(tile.x0 + x), static_cast<kuint>(y),
                             a.first_hits[(y - tile.y0) * w + x], &a.aux[x]);
      frame.target->store_aux(y, tile.x0, a.aux, static_cast<size_t>(w));
    }
    return;
  }
  for (int i = 0; i < n; ++i)
    a.dirs[i] = k_camera_direction(&frame.camera, static_cast<float>(tile.x0 + i % w) + 0.5f,
                                   static_cast<float>(tile.y0 + i / w) + 0.5f);
  trace_camera_packets(ctx, v3_load(frame.camera.origin), n, a);
  for (int y = tile.y0; y < tile.y1; ++y) {
    const uint64_t before = ctx.rays;
    for (int x = 0; x < w; ++x) {
      const int i = (y - tile.y0) * w + x;
      ctx.primed_hit = &a.hits[i];
      ctx.primed_found = a.found[i];
      ctx.primed_dir = a.dirs[i];
      k_pixel_aux(&ctx, &frame.camera, &frame.previous_camera, &frame.history,
                  static_cast<kuint>(tile.x0 + x), static_cast<kuint>(y), &a.aux[x]);
      ctx.primed_hit = nullptr;
    }
    frame.target->store_aux(y, tile.x0, a.aux, static_cast<size_t>(w));
    row_rays[y - tile.y0] += ctx.rays - before;
  }
}

}  // namespace cohort::tracers::embree_tiles
