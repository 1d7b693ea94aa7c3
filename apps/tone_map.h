// Display transform for written frames: exposure, ACES filmic curve (Narkowicz's fit), gamma.
#pragma once

#include <cstdint>
#include <vector>

#include "cohort/core/frame_buffer.h"

namespace cohort::app {

struct ToneMapOptions {
  float exposure = 1.0f;
  float gamma = 2.2f;
};

std::vector<uint8_t> tone_map(const core::FrameBuffer& frame, const ToneMapOptions& options = {});

}  // namespace cohort::app
