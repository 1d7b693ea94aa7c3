// The BVH debug view (K_MODE_BVH) under Embree. Embree does not expose how many nodes a ray visits, so
// this view traces Cohort's own two-level BVH (the one the OpenCL and CUDA tracers traverse, kept in
// every tracer's scene copy) with the portable traversal (kernel/trace_bvh.h) and shows its cost: the
// heat map is that BVH's, not Embree's. Kept in its own file: it instantiates the integrator a second
// time, on the portable traversal instead of Embree.
#pragma once

#include "cohort/kernel/scene_view.h"

namespace cohort::tracers::embree_bvh_view {

// Pixel (x, y) of the heat map, as k_render_pixel renders it in K_MODE_BVH.
KVec3 render_pixel(const KSceneView& scene, const KFrameParams& params, const KCamera& camera, kuint x, kuint y);

}  // namespace cohort::tracers::embree_bvh_view
