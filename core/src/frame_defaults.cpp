#include "cohort/core/frame_defaults.h"

#include <stdexcept>

namespace cohort::core {

KFrameParams default_frame_params() {
  KFrameParams p{};
  p.spp = 1;
  p.max_bounces = 1;
  p.light_samples = 1;
  // In-range (one light among those whose volume holds the hit: at equal time a third of the tree's noise on the
  // large map) on maps where a few lights overlap, which is every Doom 3 map measured; the dense rooms' bounded
  // pick where many do (1,024 lights cost 1.4x 8 on the CPU instead of 4.6x). docs/integrator.md, "Dense rooms".
  p.light_sampling = K_LIGHTS_AUTO;
  p.emissive_samples = 1;
  p.firefly_clamp = 5.0f;
  p.spec_boost = 2.0f;
  p.mode = K_MODE_PATH;
  p.soft_shadow_scale = 0.2f;
  p.rr_start = 2.0f;
  // Shadow-ray roulette below 0.03 of a unit of radiance: the large map at 1080p 12.9 -> 9.7 ms a frame on
  // one H100 for +0.7% RMSE on the test map at equal spp, none measurable on the large map
  // (docs/integrator.md, "Russian roulette on shadow rays").
  p.shadow_rr = 0.03f;
  return p;
}

const std::vector<std::string>& light_sampling_names() {
  static const std::vector<std::string> names = {"tree", "all", "every", "gather", "in-range", "dense", "auto"};
  return names;
}

kuint light_sampling_mode(const std::string& name) {
  if (name == "tree") return K_LIGHTS_TREE;
  if (name == "all") return K_LIGHTS_ALL;
  if (name == "every") return K_LIGHTS_EVERY;
  if (name == "gather") return K_LIGHTS_GATHER;
  if (name == "in-range") return K_LIGHTS_IN_RANGE;
  if (name == "dense") return K_LIGHTS_DENSE;
  if (name == "auto") return K_LIGHTS_AUTO;
  throw std::invalid_argument("light sampling '" + name + "': choose tree, all, every, gather, in-range, dense or auto");
}

const std::string& light_sampling_name(kuint mode) {
  const std::vector<std::string>& names = light_sampling_names();
  if (mode >= names.size()) throw std::invalid_argument("light sampling mode " + std::to_string(mode) + " has no name");
  return names[mode];
}

const std::vector<std::string>& aux_rays_names() {
  static const std::vector<std::string> names = {"centre", "first-hit"};
  return names;
}

kuint aux_rays_mode(const std::string& name) {
  if (name == "centre") return K_AUX_CENTRE_RAY;
  if (name == "first-hit") return K_AUX_PATH_FIRST_HIT;
  throw std::invalid_argument("aux rays '" + name + "': choose centre or first-hit");
}

}  // namespace cohort::core
