// The G-buffer the reprojection and denoiser tests start from.
#pragma once

#include "cohort/core/gbuffer.h"

namespace cohort::test {

// A flat wall facing the camera at depth 10 (this frame and the last), all world (id 0), nothing
// moving, of one grey albedo.
inline core::GBuffer still_wall(int width, int height, float albedo) {
  core::GBuffer g;
  g.resize(width, height);
  for (size_t p = 0; p < g.pixels(); ++p) {
    g.depth[p] = g.prev_depth[p] = 10.0f;
    g.normal[3 * p + 2] = 1.0f;
    g.id[p] = 0;
    for (int k = 0; k < 3; ++k) g.albedo[3 * p + k] = albedo;
  }
  return g;
}

}  // namespace cohort::test
