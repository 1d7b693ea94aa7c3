// What `cohort play --frames N` reports when it quits: the frame interval it held (median, 95th
// percentile, frames per second) after a warm-up, and the render size and samples the frame-rate target
// chose last, so a run can be checked against a rate without reading the HUD.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace cohort::app {

class PlayRate {
 public:
  // warmup: frames left out at the start (loading, the first frames' caches, the workload scaler settling).
  explicit PlayRate(size_t warmup) : warmup_(warmup) {}
  // After each presented frame: the wall time since the previous one, in milliseconds.
  void frame(double interval_ms);
  size_t counted() const { return intervals_.size(); }
  double median_ms() const;
  double p95_ms() const;
  // E.g. "played 200 frames in a 1280x720 window: median 31.2 ms (32.1 fps), p95 40.0 ms over the last 170;
  // rendering 320x180 (scale 0.25), 1 spp, target 30 fps".
  std::string summary(size_t frames, int window_width, int window_height, int render_width, int render_height,
                      double scale, int spp, int target_fps) const;

 private:
  size_t warmup_;
  size_t seen_ = 0;
  std::vector<double> intervals_;
};

}  // namespace cohort::app
