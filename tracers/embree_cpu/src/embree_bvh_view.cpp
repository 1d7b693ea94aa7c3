#include "cohort/kernel/trace_bvh.h"
#include "cohort/kernel/integrator.h"

#include "embree_bvh_view.h"

namespace cohort::tracers::embree_bvh_view {

KVec3 render_pixel(const KSceneView& scene, const KFrameParams& params, const KCamera& camera, kuint x, kuint y) {
  KTraceCtx ctx;
  ctx.scene = scene;
  ctx.closest_rays = 0u;
  ctx.occlusion_rays = 0u;
  return k_render_pixel(&ctx, &params, &camera, x, y);
}

}  // namespace cohort::tracers::embree_bvh_view
