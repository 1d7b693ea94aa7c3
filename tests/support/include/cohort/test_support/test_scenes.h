// The scenes the tests build in memory, so that they need no files (the test map on disk is
// tools/testmap's assets/testmap).
#pragma once

#include "cohort/scene/scene.h"

namespace cohort::test {

// A small scene in the shape of the test map: a door, a fan and a flickering light, named as the
// scenario (cohort/scene/scenario.h) expects, plus a fill light and a player start. Entity i and light
// i get RenderWorld handle i: 0 player start, 1 door, 2 fan; 0 flicker, 1 fill. For the RenderWorld,
// delta stream, scenario and world sync tests.
scene::Scene small_test_map();

// A closed room (400 x 300 x 200) exercising most of the material and light paths: a checkered
// sRGB floor with a normal map and a specular map, an emissive panel, a pillar entity, an
// alpha-tested grate entity, an additive glow decal, a point light, a projected light with a gel and
// a falloff image, and a parallel light. For the tracer tests.
scene::Scene test_room();

// A square floor in z = 0 spanning [-half, half]^2, facing +Z, as the scene's only area.
scene::Scene floor_scene(float half, glm::vec3 albedo);

// A closed cube [-half, half]^3 whose inside walls all have this albedo and emission.
scene::Scene furnace_box(float half, float albedo, float emission);

// A 2000 x 2000 floor (z = 0, albedo 0.7) under randomly placed point lights (radii 150-450, 30-160
// units up) and projected lights shining down from 300 units, of random colours, overlapping a few deep
// everywhere: for light-sampling tests and benchmarks.
scene::Scene many_lights_floor(int point_lights, int projected_lights, unsigned seed = 11);
// A 120 x 120 emissive panel 150 units up over the origin (two emissive triangles, facing down, radiance
// 4, 3.5, 3): its material and a world mesh of its own added to the scene.
void add_emissive_panel(scene::Scene& s);
// many_lights_floor under that panel: lights and emitters for next-event estimation at once (the
// wavefronts' shadow-walk tests).
scene::Scene many_lights_floor_under_a_panel(int point_lights, int projected_lights);

}  // namespace cohort::test
