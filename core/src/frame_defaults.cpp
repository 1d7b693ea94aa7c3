#include "cohort/core/frame_defaults.h"

namespace cohort::core {

KFrameParams default_frame_params() {
  KFrameParams p{};
  p.spp = 1;
  p.max_bounces = 1;
  p.light_samples = 1;
  p.firefly_clamp = 5.0f;
  p.spec_boost = 2.0f;
  p.mode = K_MODE_PATH;
  p.soft_shadow_scale = 0.2f;
  p.rr_start = 2.0f;
  return p;
}

}  // namespace cohort::core
