// Skinned characters in the Embree tracer: the tracer scene's vertices are skinned on the host when a
// commit is applied (commit::skin_on_host, TBB over the vertices, and the portable BLAS refit); these
// bring Embree's own BVHs of those BLASes along. Kept apart from the tracer's scene building.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <vector>

#include "cohort/commit/tracer_scene.h"

namespace cohort::tracers::embree_skinned {

// Whether BLAS `blas` is written by a skin (its vertices move every frame).
bool is_skinned(const commit::TracerScene& scene, uint32_t blas);

// Build settings for a skinned BLAS's geometry and scene: refit rather than rebuild when vertices move.
void prepare(RTCScene blas_scene, RTCGeometry geometry);

// After the posed skins' vertices changed: each one's Embree geometry is told its vertex buffer changed
// and its scene recommitted (a refit). The instance scene must then be rebuilt for the new bounds.
void refit(const commit::TracerScene& scene, const std::vector<uint32_t>& posed_skins,
           const std::vector<RTCScene>& blas_scenes);

}  // namespace cohort::tracers::embree_skinned
