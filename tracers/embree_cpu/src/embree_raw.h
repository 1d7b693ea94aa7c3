// Rays traced on an Embree scene with nothing around them (no shading, no ray generation), through
// each of Embree's ray APIs: the yardstick bench_tracers holds the integrator's ray rate against.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <vector>

#include "cohort/kernel/scene_view.h"
#include "cohort/tracers/embree_tracer.h"

namespace cohort::tracers::embree_kernel {
struct SplitBlas;
}

namespace cohort::tracers::embree_raw {

// How many of the rays hit (occlusion = false) or are occluded, traced with `api` on `top` through the
// integrator's filter function (instance masks, alpha tests); split: the scene's split BLASes (may be null).
// Spread over the cores in chunks by TBB.
uint64_t trace(RTCScene top, const KSceneView& scene, const embree_kernel::SplitBlas* split,
               const std::vector<EmbreeRay>& rays, bool occlusion, EmbreeRayApi api, bool coherent);

}  // namespace cohort::tracers::embree_raw
