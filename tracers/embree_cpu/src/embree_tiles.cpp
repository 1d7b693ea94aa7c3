#include "embree_kernel.h"

#include "cohort/kernel/integrator.h"

#include "embree_bvh_view.h"
#include "embree_tile_steps.h"
#include "embree_tiles.h"

// Built twice (CMakeLists.txt): as render_tile for any x86-64, and with -march=x86-64-v3 as
// render_tile_x86_64_v3. Nothing here may instantiate a template or inline function with external
// linkage: the linker could hand the baseline build the v3 copy.
#ifndef COHORT_RENDER_TILE
#define COHORT_RENDER_TILE render_tile
#endif

namespace cohort::tracers::embree_tiles {

namespace {

// k_path_segment for one path, its emissive pick through emissive_picks like the wavefront's.
int path_segment(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, const KHit* traced,
                 KPathFirstHit* first_hit, KShadowQueue* shadows, KVertexLight* vertex) {
  KLitVertex lit;
  const int shaded = path_segment_lit(ctx, params, s, traced, first_hit, shadows, vertex, &lit);
  if (shaded != K_PATH_VERTEX_LIT) return shaded;
  KEmissivePick pick{K_NONE, 0.0f};
  if (lit.emissive_nee) {
    const float u = emissive_pick_number(lit);
    emissive_picks(&ctx->scene, 1, &lit.sf.position, &u, &pick);
  }
  return path_vertex_end(ctx, params, s, &lit, lit.emissive_nee ? &pick : nullptr, shadows, vertex);
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
      // k_trace_path's loop, through path_segment (embree_tile_steps.h).
      if (first_hit) k_record_first_hit(first_hit, K_NONE, 0u, 0u);
      KPathState path;
      k_path_begin(&path, org, a.dirs[j], pixel_spread, a.rngs[i]);
      KShadowQueue shadows = k_shadow_queue_inline();
      KVertexLight vertex;
      while (path_segment(&ctx, params, &path, nullptr, first_hit, &shadows, &vertex)) {
      }
      a.sums[i] = v3_add(a.sums[i], path.radiance);
      ctx.primed_hit = nullptr;
      row_rays[i / w] += ctx.rays - before;
    }
  }
  store_rows(frame, tile, a, ctx, row_rays, 1.0f / static_cast<float>(spp));
}

}  // namespace cohort::tracers::embree_tiles
