// Which BLASes need Embree's filter function (filter_hit): only those a ray can pass through somewhere
// (k_hit_transmittance: pass-through, transparent, alpha-tested, noShadows or translucent materials).
// Every other candidate hit is final, and Embree finds it without calling back per candidate. Instance
// masks are Embree's own ray masks where the device supports them; otherwise every BLAS keeps the
// filter, which then applies the masks too.
#pragma once

#include <vector>

#include "cohort/commit/tracer_scene.h"

namespace cohort::tracers::embree_filters {

// Per BLAS: whether one of its triangles' own materials may let a camera or shadow ray pass.
std::vector<char> blases_with_passing_materials(const commit::TracerScene& scene);

// Whether triangle t's own material may let a camera or shadow ray pass.
bool triangle_may_pass(const commit::TracerScene& scene, size_t t);

// Per BLAS: whether an instance of it overrides its materials with one that may let a ray pass (then every
// triangle of it needs the filter function); every BLAS when the device applies no ray masks.
std::vector<char> blases_with_passing_overrides(const commit::TracerScene& scene, bool device_ray_masks);

// Per BLAS: whether it needs the filter function, given blases_with_passing_materials and the instances'
// material overrides; every BLAS when the device applies no ray masks.
std::vector<char> blases_needing_filters(const commit::TracerScene& scene, const std::vector<char>& own_materials,
                                         bool device_ray_masks);

}  // namespace cohort::tracers::embree_filters
