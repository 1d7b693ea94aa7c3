// A tile as a wavefront: the GPU tracers' stages (kernel/wave_shade.h, wave_walk.h) run over the tile's
// pixels on one core, so that shadow and bounce rays reach Embree in packets instead of one by one. Per
// sample: the camera rays in coherent packets; every path's segment shaded up to its next bounce
// (k_path_segment), its vertex's shadow rays left in the tile's slots; all of them traced together in
// packets, then each vertex's light added in the integrator's order (k_wave_shadow_finish_pixel); the live
// paths' bounce rays in packets; shaded again, until no path is live. Same integrator, same random
// numbers, same rays and the same order of float additions as render_tile: the same image, bit for bit
// (EmbreeWavefront.*). Transparent layers are still walked inside a segment, one ray at a time, as are a
// vertex's shadow rays when it may emit more than its slots (`every` past K_SHADOW_QUEUE_MAX lights).
#include "embree_kernel.h"

#include "cohort/kernel/integrator.h"
#include "cohort/kernel/wave_shade.h"
#include "cohort/kernel/wave_walk.h"

#include "embree_tile_steps.h"
#include "embree_tiles.h"

// Built twice (CMakeLists.txt): as render_wave_tile for any x86-64, and with -march=x86-64-v3 as
// render_wave_tile_x86_64_v3. Nothing here may instantiate a template or inline function with external
// linkage: the linker could hand the baseline build the v3 copy (templates stay in the anonymous namespace).
#ifndef COHORT_RENDER_WAVE_TILE
#define COHORT_RENDER_WAVE_TILE render_wave_tile
#endif

namespace cohort::tracers::embree_tiles {

namespace {

static_assert(K_SHADOW_QUEUE_MAX <= 8u, "a shadow ray to trace is kept as pixel * 8 + slot");
static_assert(kTilePixels * 8 <= 65536, "a shadow ray to trace is kept in 16 bits");

// rtcIntersect8/16, rtcOccluded8/16 by packet width.
template <int W>
struct Packets;
template <>
struct Packets<8> {
  using Ray = RTCRay8;
  using RayHit = RTCRayHit8;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) {
    rtcIntersect8(valid, s, c, r);
  }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) {
    rtcOccluded8(valid, s, c, r);
  }
};
template <>
struct Packets<16> {
  using Ray = RTCRay16;
  using RayHit = RTCRayHit16;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) {
    rtcIntersect16(valid, s, c, r);
  }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) {
    rtcOccluded16(valid, s, c, r);
  }
};

// One lane of a packet: the ray from org along dir up to tmax, seeing the instances of mask.
template <class Ray>
void fill_lane(Ray& r, int k, KVec3 org, KVec3 dir, float tmax, kuint mask) {
  r.org_x[k] = org.x; r.org_y[k] = org.y; r.org_z[k] = org.z;
  r.dir_x[k] = dir.x; r.dir_y[k] = dir.y; r.dir_z[k] = dir.z;
  r.tnear[k] = 0.0f;
  r.tfar[k] = tmax;
  r.mask[k] = mask;
  r.time[k] = 0.0f;
  r.id[k] = static_cast<unsigned>(k);
  r.flags[k] = 0u;
}

// Lane k's closest hit into path p's KHit (instance K_NONE: a miss), counted in its pixel's row and logged.
template <class RayHit>
void take_hit(embree_kernel::TraceCtx& ctx, Arena& a, const RayHit& rh, int k, int p, int tile_width,
              uint64_t* row_rays, embree_kernel::RayClass ray_class) {
  namespace ek = embree_kernel;
  KHit& hit = a.wave.hits[p];
  hit.cost = 0u;
  hit.pad0 = hit.pad1 = 0u;
  row_rays[p / tile_width] += 1u;
  if (ctx.log)
    ek::log_ray(ctx.log, ray_class, v3(rh.ray.org_x[k], rh.ray.org_y[k], rh.ray.org_z[k]),
                v3(rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]), K_INF, K_RAY_PRIMARY);
  if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
    hit.instance = K_NONE;
    return;
  }
  hit.t = rh.ray.tfar[k];
  hit.u = rh.hit.u[k];
  hit.v = rh.hit.v[k];
  hit.instance = rh.hit.instID[0][k];
  hit.triangle = ek::scene_triangle(ctx.scene, ctx.split, hit.instance, rh.hit.geomID[k], rh.hit.primID[k]);
}

// The tile's n paths a.wave.pixels[0..n) walk their closest-hit rays (ray(j, &org, &dir) for the j-th; tmax
// infinite, camera and bounce rays' mask) in packets of W; each hit into a.wave.hits[pixel] (take_hit).
// coherent: camera rays (one origin, neighbouring directions).
template <int W, class RayOf>
void walk_closest_packets(embree_kernel::TraceCtx& ctx, Arena& a, int n, bool coherent,
                          embree_kernel::RayClass ray_class, int tile_width, uint64_t* row_rays, RayOf ray) {
  namespace ek = embree_kernel;
  ek::FilterContext fc = ek::filter_context(&ctx.scene, ctx.split, false, coherent);
  for (int first = 0; first < n; first += W) {
    alignas(64) typename Packets<W>::RayHit rh;
    alignas(64) int valid[W];  // Embree loads the mask as one vector: unaligned, it faults on AVX-512 CPUs
    for (int k = 0; k < W; ++k) {
      const int j = first + k < n ? first + k : n - 1;  // unused lanes repeat the last ray, masked off
      valid[k] = first + k < n ? -1 : 0;
      KVec3 org, dir;
      ray(j, &org, &dir);
      fill_lane(rh.ray, k, org, dir, K_INF, K_RAY_PRIMARY);
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    Packets<W>::intersect(valid, ctx.top, &fc.base, &rh);
    for (int k = 0; k < W && first + k < n; ++k)
      take_hit(ctx, a, rh, k, a.wave.pixels[first + k], tile_width, row_rays, ray_class);
  }
  ctx.rays += static_cast<uint64_t>(n);
}

template <class RayOf>
void walk_closest(embree_kernel::TraceCtx& ctx, Arena& a, int n, bool coherent, embree_kernel::RayClass ray_class,
                  int tile_width, uint64_t* row_rays, int packets, RayOf ray) {
  if (packets == 16)
    walk_closest_packets<16>(ctx, a, n, coherent, ray_class, tile_width, row_rays, ray);
  else
    walk_closest_packets<8>(ctx, a, n, coherent, ray_class, tile_width, row_rays, ray);
}

// A shadow ray's outcome: unblocked, its slot's bit in its pixel's visible bits; counted and logged.
void take_shadow(embree_kernel::TraceCtx& ctx, Arena& a, int e, bool occluded, int tile_width, uint64_t* row_rays) {
  namespace ek = embree_kernel;
  const int p = e >> 3;
  if (!occluded) a.wave.visible[p] |= 1u << (e & 7);
  row_rays[p / tile_width] += 1u;
  if (ctx.log) {
    const KShadowRay& s = a.wave.shadow_rays[(e & 7) * kTilePixels + p];
    ek::log_ray(ctx.log, ek::kShadowRay, s.org, s.dir, s.tmax, s.mask & ~K_SHADOW_RAY_EMISSIVE);
  }
}

// The tile's shadow rays to trace (a.wave.shadows[0..rays)) in packets of W. Incoherent: the coherent flag
// made rtcOccluded16 never finish (docs/embree-tracer.md).
template <int W>
void trace_shadow_packets(embree_kernel::TraceCtx& ctx, Arena& a, int rays, int tile_width, uint64_t* row_rays) {
  namespace ek = embree_kernel;
  Arena::Wave& wv = a.wave;
  ek::FilterContext fc = ek::filter_context(&ctx.scene, ctx.split, true);
  for (int first = 0; first < rays; first += W) {
    alignas(64) typename Packets<W>::Ray r;
    alignas(64) int valid[W];
    for (int k = 0; k < W; ++k) {
      const int e = wv.shadows[first + k < rays ? first + k : rays - 1];
      valid[k] = first + k < rays ? -1 : 0;
      const KShadowRay& s = wv.shadow_rays[(e & 7) * kTilePixels + (e >> 3)];
      fill_lane(r, k, s.org, s.dir, s.tmax, s.mask & ~K_SHADOW_RAY_EMISSIVE);
    }
    Packets<W>::occluded(valid, ctx.top, &fc.base, &r);
    for (int k = 0; k < W && first + k < rays; ++k)  // Embree sets tfar to -inf on occlusion
      take_shadow(ctx, a, wv.shadows[first + k], r.tfar[k] < 0.0f, tile_width, row_rays);
  }
}

// The shadow rays the shaded vertices of the traced pixels left in their slots, all traced together in
// packets of any mix of masks (the filter reads each lane's), then each vertex's light added
// (k_wave_shadow_finish_pixel): k_wave_shadow_walk_pixel for the whole tile, its walks batched. A ray whose
// tmax says it needs no walk (k_shadow_ray_visible) is visible untraced, as there.
void walk_shadows(embree_kernel::TraceCtx& ctx, const KFrameParams* params, Arena& a, const int* traced, int n,
                  kuint sample, int tile_width, uint64_t* row_rays, int packets) {
  Arena::Wave& wv = a.wave;
  int rays = 0;
  for (int j = 0; j < n; ++j) {
    const int p = traced[j];
    if (!(wv.active[p] & K_WAVE_SHADOWS_OUT)) continue;
    wv.visible[p] = 0u;
    for (kuint k = 0u; k < wv.vertices[p].ray_count; ++k) {
      if (wv.shadow_rays[k * kTilePixels + p].tmax <= 0.0f)
        wv.visible[p] |= 1u << k;
      else
        wv.shadows[rays++] = static_cast<uint16_t>(p * 8 + static_cast<int>(k));
    }
  }
  if (packets == 16)
    trace_shadow_packets<16>(ctx, a, rays, tile_width, row_rays);
  else
    trace_shadow_packets<8>(ctx, a, rays, tile_width, row_rays);
  ctx.rays += static_cast<uint64_t>(rays);
  for (int j = 0; j < n; ++j) {
    const int p = traced[j];
    if (wv.active[p] & K_WAVE_SHADOWS_OUT)
      k_wave_shadow_finish_pixel(params, static_cast<size_t>(p), sample, wv.active[p], wv.vertices[p].ray_count,
                                 wv.visible[p], wv.band, wv.states, wv.active, wv.vertices, wv.shadow_rays, kTilePixels);
  }
}

}  // namespace

void COHORT_RENDER_WAVE_TILE(const Frame& frame, const Tile& tile, Arena& a, embree_kernel::RayLog* log,
                             uint64_t row_rays[kTileHeight]) {
  embree_kernel::TraceCtx ctx = frame.base;
  ctx.log = log;
  ctx.primed_hit = nullptr;
  Arena::Wave& wv = a.wave;
  const int w = tile.x1 - tile.x0, n = w * (tile.y1 - tile.y0);
  const KFrameParams* params = &frame.params;
  const KCamera* camera = &frame.camera;
  const kuint spp = k_paths_per_pixel(params->spp);
  const KVec3 org = v3_load(camera->origin);
  const int shadow_walk = frame.shadow_slots > 0u;
  // Sparse paths (dynamic resolution): only the pattern's pixels trace, packed so packets stay full; the
  // others stay black (their aux planes are written anyway).
  int traced = 0;
  for (int i = 0; i < n; ++i) {
    if (k_pixel_traces_path(params->path_pixels, params->path_phase, static_cast<kuint>(tile.x0 + i % w),
                            static_cast<kuint>(tile.y0 + i / w)))
      a.traced[traced++] = i;
    else
      for (int c = 0; c < 4; ++c) wv.band[4 * i + c] = c == 3 ? 1.0f : 0.0f;
  }
  const bool record_first_hits = frame.write_aux && frame.target && k_aux_from_paths(params);

  for (kuint s = 0u; s < spp; ++s) {
    // The segments of the paths a stage shades (camera_rays: the paths begin, from their camera rays' hits),
    // then the shadow rays they left. k_path_segment in three steps over all of them: each path up to its opaque
    // vertex's Doom 3 lights (the vertex, its path and shadow queue then wait in the arena), the waiting
    // vertices' emissive picks eight at a time, then each vertex's shading ended.
    auto shade = [&](int camera_rays) {
      KPathFirstHit* records = s == 0u && record_first_hits && camera_rays ? a.first_hits : nullptr;
      int lit = 0, picking = 0;
      for (int j = 0; j < traced; ++j) {
        const int p = a.traced[j];
        if (!k_wave_shades(1, static_cast<size_t>(p), wv.active, camera_rays)) continue;
        const kuint x = static_cast<kuint>(tile.x0 + p % w), y = static_cast<kuint>(tile.y0 + p / w);
        const uint64_t before = ctx.rays;
        if (log) log->camera_dir = a.dirs[j];  // closest rays along it (through transparent layers) are camera rays
        KPathState path;
        KHit hit;
        KShadowQueue shadows;
        k_wave_path_load(params, camera, x, y, static_cast<size_t>(p), s, wv.states, wv.hits, wv.shadow_rays,
                         kTilePixels, camera_rays, shadow_walk, &path, &hit, &shadows);
        KVertexLight vertex;
        const int shaded = path_segment_lit(&ctx, params, &path, &hit, records ? records + p : nullptr, &shadows,
                                            &vertex, &wv.lit[p]);
        row_rays[p / w] += ctx.rays - before;
        if (shaded == K_PATH_VERTEX_LIT) {
          wv.states[p] = path;
          wv.queued[p] = shadows.count;
          wv.vertices[p] = vertex;
          wv.lit_paths[lit++] = j;
          if (wv.lit[p].emissive_nee) {
            wv.pick_points[picking] = wv.lit[p].sf.position;
            wv.pick_numbers[picking++] = emissive_pick_number(wv.lit[p]);
          }
          continue;
        }
        k_wave_path_store(params, static_cast<size_t>(p), s, shaded, &path, &shadows, &vertex, wv.band, wv.states,
                          wv.active, wv.vertices, camera_rays);
      }
      emissive_picks(&ctx.scene, picking, wv.pick_points, wv.pick_numbers, wv.picks);
      for (int i = 0, picked = 0; i < lit; ++i) {
        const int j = wv.lit_paths[i], p = a.traced[j];
        const uint64_t before = ctx.rays;
        if (log) log->camera_dir = a.dirs[j];
        KPathState path;
        KHit hit;
        KShadowQueue shadows;  // as the first step had it
        k_wave_path_load(params, camera, 0u, 0u, static_cast<size_t>(p), s, wv.states, wv.hits, wv.shadow_rays,
                         kTilePixels, 0, shadow_walk, &path, &hit, &shadows);
        shadows.count = wv.queued[p];
        KVertexLight vertex = wv.vertices[p];
        const KEmissivePick* pick = wv.lit[p].emissive_nee ? &wv.picks[picked++] : nullptr;
        const int goes_on = path_vertex_end(&ctx, params, &path, &wv.lit[p], pick, &shadows, &vertex);
        k_wave_path_store(params, static_cast<size_t>(p), s, goes_on, &path, &shadows, &vertex, wv.band, wv.states,
                          wv.active, wv.vertices, camera_rays);
        row_rays[p / w] += ctx.rays - before;
      }
      if (shadow_walk) walk_shadows(ctx, params, a, a.traced, traced, s, w, row_rays, frame.packet_width);
    };

    for (int j = 0; j < traced; ++j) {
      const int p = a.traced[j];
      KRng rng;
      a.dirs[j] = k_camera_sample(params, camera, static_cast<kuint>(tile.x0 + p % w),
                                  static_cast<kuint>(tile.y0 + p / w), s, &rng);
      wv.pixels[j] = p;
      if (s == 0u && record_first_hits) k_record_first_hit(&a.first_hits[p], K_NONE, 0u, 0u);
    }
    walk_closest(ctx, a, traced, true, embree_kernel::kCameraRay, w, row_rays, frame.packet_width,
                 [&](int j, KVec3* o, KVec3* d) {
                   *o = org;
                   *d = a.dirs[j];
                 });
    shade(1);
    for (;;) {
      int live = 0;
      for (int j = 0; j < traced; ++j)
        if (wv.active[a.traced[j]] & K_WAVE_LIVE) wv.pixels[live++] = a.traced[j];
      if (live == 0) break;
      walk_closest(ctx, a, live, false, embree_kernel::kBounceRay, w, row_rays, frame.packet_width,
                   [&](int j, KVec3* o, KVec3* d) {
                     *o = wv.states[wv.pixels[j]].org;
                     *d = wv.states[wv.pixels[j]].dir;
                   });
      shade(0);
    }
  }

  if (frame.target)
    for (int y = tile.y0; y < tile.y1; ++y)
      frame.target->store(y, tile.x0, wv.band + 4 * (y - tile.y0) * w, static_cast<size_t>(w),
                          frame.params.frame_index);
  if (frame.write_aux && frame.target) write_aux(frame, tile, a, ctx, row_rays);
}

}  // namespace cohort::tracers::embree_tiles
