// The defaults every front end starts from (render, play, benches, tests): one place, so the same
// options give the same image wherever they are set.
#pragma once

#include <string>
#include <vector>

#include "cohort/kernel/layout.h"

namespace cohort::core {

constexpr int kDefaultWidth = 640;
constexpr int kDefaultHeight = 360;

// Path tracing, 1 spp, next-event estimation with one light sample picked among the lights in range (or, where
// many overlap, by the dense rooms' bounded pick: K_LIGHTS_AUTO) and
// one emissive-triangle sample (MIS with the bounce), plus one bounce, Doom 3's 2x
// specular boost, fireflies clamped at 5, soft shadows at 0.2 of a light's extent, Russian roulette
// from the second bounce. The band (row_begin, row_end) is left empty for the caller.
KFrameParams default_frame_params();

// The light-sampling modes by their command-line names: "tree" (K_LIGHTS_TREE), "all" (K_LIGHTS_ALL), "every"
// (K_LIGHTS_EVERY), "gather" (K_LIGHTS_GATHER), "in-range" (K_LIGHTS_IN_RANGE), "dense" (K_LIGHTS_DENSE) and
// "auto" (K_LIGHTS_AUTO, the default: in-range or dense by the scene, core/light_sampling.h), in that order.
const std::vector<std::string>& light_sampling_names();
// Throws std::invalid_argument naming the choices for any other name.
kuint light_sampling_mode(const std::string& name);
// The command-line name of a mode (the command lines' defaults: default_frame_params()'s); throws
// std::invalid_argument for a mode with no name.
const std::string& light_sampling_name(kuint mode);

// Where the aux planes come from, by command-line name (--aux-rays): "centre" (K_AUX_CENTRE_RAY) and
// "first-hit" (K_AUX_PATH_FIRST_HIT), in that order. The command line's default, "auto", is resolved by the
// tracers first (tracers::auto_aux_rays).
const std::vector<std::string>& aux_rays_names();
// KFrameParams.aux_outputs for a frame that wants the planes; throws std::invalid_argument naming the choices.
kuint aux_rays_mode(const std::string& name);

}  // namespace cohort::core
