// Adaptive convergence (Brigade, §4.7): each new noisy frame is blended into the accumulated image,
// C = (1 - f) * C_prev + f * C_new per pixel. While nothing moves f = 1/(n+1), so the image converges
// to the average of every frame since the view settled; camera motion raises f (old samples are for
// another view), and pixels a motion mask marks as moving objects get a higher f so they do not ghost.
// A cut (a jump in position or view direction, or a resolution change) restarts from the new frame.
#pragma once

#include <cstdint>
#include <vector>

#include "cohort/core/frame_buffer.h"
#include "cohort/kernel/brigade_blend.h"
#include "cohort/kernel/layout.h"

namespace cohort::core {

struct ConvergenceOptions {
  // Camera motion that, on its own, makes f reach 1 (all of last frame's samples are discarded).
  double full_translation = 64.0;      // world units per frame (Doom: 64 units ~ 1.6 m)
  double full_rotation_degrees = 20.0; // degrees per frame
  // Lowest f while the camera moves at all: keeps blurring/ghosting short behind motion.
  double moving_floor = 0.1;
  // f for pixels fully covered by the motion mask (mask value 1); scaled by the mask value.
  double moving_object_f = 0.5;
  // Changes this large are cuts: f = 1 and accumulation restarts.
  double cut_translation = 256.0;
  double cut_rotation_degrees = 45.0;
  // While static f stops falling at 1/max_frames, so a long still view stays a running average
  // with float precision to spare.
  int max_frames = 4096;
};

class AdaptiveConvergence {
 public:
  explicit AdaptiveConvergence(ConvergenceOptions options = {}) : options_(options) {}

  // f for a frame seen through `camera`, given the previous frame's camera; advances the state.
  double next_factor(const KCamera& camera);
  // Blends `fresh` into the accumulated image with the factor from next_factor(camera).
  // motion_mask (optional): one value in [0, 1] per pixel, 1 = a moving object covers it.
  // Returns the global f used.
  double accumulate(const KCamera& camera, const FrameBuffer& fresh, const std::vector<float>* motion_mask = nullptr);
  // The blend alone, with a factor chosen elsewhere (a post that blends, core/frame_post.h): f >= 1, or a
  // frame of another size, starts the image over from `fresh`.
  void blend(const FrameBuffer& fresh, double f, const std::vector<float>* motion_mask = nullptr);
  const FrameBuffer& image() const { return accumulated_; }
  // Frames the accumulated image is worth (1/f of the last blend).
  double effective_frames() const { return effective_frames_; }
  void reset();

 private:
  ConvergenceOptions options_;
  FrameBuffer accumulated_;
  KCamera previous_{};
  bool have_previous_ = false;
  double effective_frames_ = 0.0;
};

// Per-pixel blend, exposed for tests: returns (1 - f) * previous + f * fresh (kernel/brigade_blend.h, which
// a GPU's post runs too).
inline float converge(float previous, float fresh, float f) { return k_brigade_blend(previous, fresh, f); }

}  // namespace cohort::core
