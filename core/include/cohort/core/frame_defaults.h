// The defaults every front end starts from (render, play, benches, tests): one place, so the same
// options give the same image wherever they are set.
#pragma once

#include "cohort/kernel/layout.h"

namespace cohort::core {

constexpr int kDefaultWidth = 640;
constexpr int kDefaultHeight = 360;

// Path tracing, 1 spp, next-event estimation with one light sample plus one bounce, Doom 3's 2x
// specular boost, fireflies clamped at 5, soft shadows at 0.2 of a light's extent, Russian roulette
// from the second bounce. The band (row_begin, row_end) is left empty for the caller.
KFrameParams default_frame_params();

}  // namespace cohort::core
