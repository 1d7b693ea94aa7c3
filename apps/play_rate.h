// What `cohort play --frames N` reports when it quits: the frame interval it held (median, 95th
// percentile, frames per second) after a warm-up, and the render size and samples the frame-rate target
// chose last, so a run can be checked against a rate without reading the HUD. It also says how much CPU
// time the process took per frame: on a machine shared with other work the frame rate says little about
// what a machine of its own would hold, the CPU time a frame costs says more.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace cohort::app {

class PlayRate {
 public:
  // warmup: frames left out at the start (loading, the first frames' caches, the workload scaler settling).
  explicit PlayRate(size_t warmup) : warmup_(warmup) {}
  // After each presented frame: the wall time since the previous one and, where known, the process's CPU
  // time (every thread) over the same span, in milliseconds.
  void frame(double interval_ms, double cpu_ms = -1.0);
  size_t counted() const { return intervals_.size(); }
  double median_ms() const;
  double p95_ms() const;
  // CPU milliseconds per counted frame and the cores that makes busy (CPU time / wall time); 0 when the
  // CPU time was not given.
  double cpu_ms_per_frame() const;
  double cores_busy() const;
  // E.g. "played 200 frames in a 1280x720 window: median 31.2 ms (32.1 fps), p95 40.0 ms over the last 170,
  // CPU 58.1 ms a frame (1.84 cores); rendering 320x180 (scale 0.25), 1 spp, target 30 fps".
  std::string summary(size_t frames, int window_width, int window_height, int render_width, int render_height,
                      double scale, int spp, int target_fps) const;

 private:
  size_t warmup_;
  size_t seen_ = 0;
  std::vector<double> intervals_;
  double timed_ms_ = 0.0, cpu_ms_ = 0.0;  // over the counted frames that came with a CPU time
  size_t cpu_frames_ = 0;
};

// The CPU time this process has used so far, all threads, in milliseconds.
double process_cpu_ms();

}  // namespace cohort::app
