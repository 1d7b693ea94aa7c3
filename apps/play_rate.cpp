#include "play_rate.h"

#include <algorithm>
#include <cmath>
#include <ctime>

#include <fmt/format.h>

#include "cohort/balance/order_statistics.h"

namespace cohort::app {

void PlayRate::frame(double interval_ms, double cpu_ms) {
  if (seen_++ < warmup_ || !(interval_ms > 0.0) || !std::isfinite(interval_ms)) return;
  intervals_.push_back(interval_ms);
  if (cpu_ms >= 0.0 && std::isfinite(cpu_ms)) {
    timed_ms_ += interval_ms;
    cpu_ms_ += cpu_ms;
    ++cpu_frames_;
  }
}

double PlayRate::cpu_ms_per_frame() const { return cpu_frames_ ? cpu_ms_ / static_cast<double>(cpu_frames_) : 0.0; }
double PlayRate::cores_busy() const { return timed_ms_ > 0.0 ? cpu_ms_ / timed_ms_ : 0.0; }

double process_cpu_ms() {
  timespec t{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t) != 0) return 0.0;
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

double PlayRate::median_ms() const { return median(intervals_); }
double PlayRate::p95_ms() const { return quantile(intervals_, 0.95); }

std::string PlayRate::summary(size_t frames, int window_width, int window_height, int render_width, int render_height,
                              double scale, int spp, int target_fps) const {
  std::string text = fmt::format("played {} frames in a {}x{} window", frames, window_width, window_height);
  if (intervals_.empty()) {
    text += fmt::format(": too few to time (the first {} are warm-up)", warmup_);
  } else {
    const double median = median_ms();
    text += fmt::format(": median {:.1f} ms ({:.1f} fps), p95 {:.1f} ms over the last {}", median, 1000.0 / median,
                        p95_ms(), intervals_.size());
    if (cpu_frames_ > 0) text += fmt::format(", CPU {:.1f} ms a frame ({:.2f} cores)", cpu_ms_per_frame(), cores_busy());
  }
  text += fmt::format("; rendering {}x{} (scale {:.2f}), {} spp", render_width, render_height, scale, spp);
  text += target_fps > 0 ? fmt::format(", target {} fps", target_fps) : std::string(", no frame-rate target");
  return text;
}

}  // namespace cohort::app
