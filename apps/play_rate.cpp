#include "play_rate.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cohort/balance/order_statistics.h"

namespace cohort::app {

void PlayRate::frame(double interval_ms) {
  if (seen_++ < warmup_ || !(interval_ms > 0.0) || !std::isfinite(interval_ms)) return;
  intervals_.push_back(interval_ms);
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
  }
  text += fmt::format("; rendering {}x{} (scale {:.2f}), {} spp", render_width, render_height, scale, spp);
  text += target_fps > 0 ? fmt::format(", target {} fps", target_fps) : std::string(", no frame-rate target");
  return text;
}

}  // namespace cohort::app
