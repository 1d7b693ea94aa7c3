#include "embree_kernel.h"

#include "cohort/kernel/integrator.h"
#include "cohort/kernel/aux_outputs.h"


#include "embree_bvh_view.h"
#include "embree_tiles.h"

// Built twice (CMakeLists.txt): as render_tile for any x86-64, and with -march=x86-64-v3 as
// render_tile_x86_64_v3. Nothing here may instantiate a template or inline function with external
// linkage: the linker could hand the baseline build the v3 copy.
#ifndef COHORT_RENDER_TILE
#define COHORT_RENDER_TILE render_tile
#endif

namespace cohort::tracers::embree_tiles {

namespace {

// Closest hits of the tile's n camera rays (all from org), 8 to a packet, with a coherent context.
void trace_camera_packets(embree_kernel::TraceCtx& ctx, KVec3 org, int n, Arena& a) {
  embree_kernel::FilterContext fc = embree_kernel::filter_context(&ctx.scene, false, true);
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
      hit.triangle = embree_kernel::scene_triangle(ctx.scene, hit.instance, rh.hit.primID[k]);
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
void write_aux(const Frame& frame, const Tile& tile, Arena& a, embree_kernel::TraceCtx& ctx, uint64_t* row_rays) {
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

void store_rows(const Frame& frame, const Tile& tile, Arena& a, embree_kernel::TraceCtx& ctx, uint64_t* row_rays,
                float scale) {
  const int w = tile.x1 - tile.x0;
  if (frame.target)
    for (int y = tile.y0; y < tile.y1; ++y) {
      const KVec3* sums = a.sums + (y - tile.y0) * w;
      for (int x = 0; x < w; ++x) {
        const KVec3 c = v3_scale(sums[x], scale);
        a.rgba[4 * x + 0] = c.x;
        a.rgba[4 * x + 1] = c.y;
        a.rgba[4 * x + 2] = c.z;
        a.rgba[4 * x + 3] = 1.0f;
      }
      frame.target->store(y, tile.x0, a.rgba, static_cast<size_t>(w), frame.params.frame_index);
    }
  if (frame.write_aux && frame.target) write_aux(frame, tile, a, ctx, row_rays);
}

}  // namespace

void COHORT_RENDER_TILE(const Frame& frame, const Tile& tile, Arena& a, embree_kernel::RayLog* log,
                        uint64_t row_rays[kTileHeight]) {
  embree_kernel::TraceCtx ctx = frame.base;
  ctx.log = log;
  ctx.primed_hit = nullptr;
  const int w = tile.x1 - tile.x0, n = w * (tile.y1 - tile.y0);
  const KFrameParams* params = &frame.params;
  const KCamera* camera = &frame.camera;

  if (params->mode == K_MODE_BVH) {
    for (int i = 0; i < n; ++i) {
      a.sums[i] = embree_bvh_view::render_pixel(ctx.scene, *params, *camera, static_cast<kuint>(tile.x0 + i % w),
                                                static_cast<kuint>(tile.y0 + i / w));
      row_rays[i / w] += 1u;
    }
    store_rows(frame, tile, a, ctx, row_rays, 1.0f);
    return;
  }

  const kuint spp = k_paths_per_pixel(params->spp);
  const KVec3 org = v3_load(camera->origin);
  const float pixel_spread = k_pixel_spread(camera);
  // Sparse paths (dynamic resolution): only the pattern's pixels trace, packed so packets stay full;
  // the others stay black (their aux planes are written anyway).
  int traced = 0;
  for (int i = 0; i < n; ++i) {
    a.sums[i] = v3s(0.0f);
    if (k_pixel_traces_path(params->path_pixels, params->path_phase, static_cast<kuint>(tile.x0 + i % w),
                            static_cast<kuint>(tile.y0 + i / w)))
      a.traced[traced++] = i;
  }
  const bool record_first_hits = frame.write_aux && frame.target && k_aux_from_paths(params);
  for (kuint s = 0u; s < spp; ++s) {
    for (int j = 0; j < traced; ++j) {
      const int i = a.traced[j];
      a.dirs[j] = k_camera_sample(params, camera, static_cast<kuint>(tile.x0 + i % w),
                                  static_cast<kuint>(tile.y0 + i / w), s, &a.rngs[i]);
    }
    trace_camera_packets(ctx, org, traced, a);
    for (int j = 0; j < traced; ++j) {
      const int i = a.traced[j];
      const uint64_t before = ctx.rays;
      ctx.primed_hit = &a.hits[j];
      ctx.primed_found = a.found[j];
      ctx.primed_dir = a.dirs[j];
      if (log) log->camera_dir = a.dirs[j];
      KPathFirstHit* first_hit = s == 0u && record_first_hits ? &a.first_hits[i] : nullptr;
      a.sums[i] = v3_add(a.sums[i], k_trace_path(&ctx, params, org, a.dirs[j], pixel_spread, &a.rngs[i], first_hit));
      ctx.primed_hit = nullptr;
      row_rays[i / w] += ctx.rays - before;
    }
  }
  store_rows(frame, tile, a, ctx, row_rays, 1.0f / static_cast<float>(spp));
}

}  // namespace cohort::tracers::embree_tiles
