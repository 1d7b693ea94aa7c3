// The light-sampling cases the wavefront's shadow walk is checked on, on OpenCL
// (opencl_wavefront_test.cpp) and on CUDA (cuda_test.cpp): the same lights, samples and roulette on
// many_lights_floor_under_a_panel, so that both tracers are held to one list.
#pragma once

#include <ostream>
#include <vector>

#include "test_scenes.h"

namespace cohort::test {

struct ShadowWalkCase {
  uint32_t light_sampling, light_samples;
  float shadow_rr;
  int point_lights, projected_lights;
  const char* name;
};
inline void PrintTo(const ShadowWalkCase& c, std::ostream* os) { *os << c.name; }

inline std::vector<ShadowWalkCase> shadow_walk_cases() {
  return {ShadowWalkCase{K_LIGHTS_TREE, 1, 0.0f, 88, 8, "tree1"},
          ShadowWalkCase{K_LIGHTS_TREE, 2, 0.03f, 88, 8, "tree2_roulette"},
          ShadowWalkCase{K_LIGHTS_GATHER, 4, 0.03f, 88, 8, "gather4_roulette"},
          ShadowWalkCase{K_LIGHTS_IN_RANGE, 1, 0.03f, 88, 8, "in_range1_roulette"},
          ShadowWalkCase{K_LIGHTS_DENSE, 1, 0.03f, 88, 8, "dense1_roulette"},
          ShadowWalkCase{K_LIGHTS_EVERY, 0, 0.03f, 4, 2, "every_6_lights"},
          ShadowWalkCase{K_LIGHTS_EVERY, 0, 0.03f, 88, 8, "every_past_the_slots"}};
}

// Two samples of two-bounce paths with the case's light sampling and shadow roulette.
inline KFrameParams shadow_walk_params(const ShadowWalkCase& c, int height) {
  KFrameParams params = frame_params(K_MODE_PATH, 2, 2, height);
  params.soft_shadow_scale = 1.0f;
  params.firefly_clamp = 4.0f;
  params.frame_index = 3;
  params.light_sampling = c.light_sampling;
  params.light_samples = c.light_samples;
  params.shadow_rr = c.shadow_rr;
  return params;
}

}  // namespace cohort::test
