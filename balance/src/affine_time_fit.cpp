#include "affine_time_fit.h"

#include <algorithm>
#include <cmath>

namespace cohort::balance {

namespace {
constexpr size_t kWindow = 32;          // samples the fixed part is fit over
constexpr double kAgeWeight = 0.9;      // weight of a sample one band older
constexpr double kMinRelativeSpread = 0.15;  // below this spread of work the intercept is not trusted
constexpr double kClipSpreads = 4.0;
constexpr double kMinClip = 0.05;       // never clip within 5 % of the prediction
// The first bands teach the speed outright: the first one carries the start's one-off costs (a full
// scene upload or BVH build), and until the spread of residuals is known, a clip of 5 % a frame would
// take dozens of frames to unlearn them (seen on GPUs: a CPU tracer's band shrinking from 53 to 12 ms
// over 28 frames beside two GPUs).
constexpr size_t kLearnOutright = 3;
}  // namespace

void AffineTimeFit::add(double work, double ms) {
  if (!(work > 0.0) || !(ms > 0.0) || !std::isfinite(work) || !std::isfinite(ms)) return;
  const bool learning = samples_.size() < kLearnOutright;
  if (known_) {
    const double predicted = predict(work);
    const double limit = predicted * std::max(kMinClip, kClipSpreads * spread_);
    const double clipped = std::clamp(ms, predicted - limit, predicted + limit);
    spread_ = 0.9 * spread_ + 0.1 * std::abs(ms - predicted) / predicted;
    if (!learning) ms = clipped;
  }
  samples_.push_back({work, ms});
  if (samples_.size() > kWindow) samples_.pop_front();
  refit_fixed();
  // The variable part follows the newest band (what this view costs), given the fixed part.
  const double observed = std::max(ms - fixed_ms_, 0.02 * ms) / work;
  ms_per_work_ = known_ && !learning ? (1.0 - follow_) * ms_per_work_ + follow_ * observed : observed;
  known_ = true;
}

void AffineTimeFit::refit_fixed() {
  // Weighted least squares of ms against work over the window, newer samples weighing more. Only
  // when the bands differed enough in size does the intercept mean something; otherwise the last
  // fixed part stays (at first 0: all cost is taken as per-work, Perfect's assumption).
  double weight = 1.0, sw = 0.0, sx = 0.0, st = 0.0, min_ms = samples_.back().ms;
  for (auto it = samples_.rbegin(); it != samples_.rend(); ++it, weight *= kAgeWeight) {
    sw += weight;
    sx += weight * it->work;
    st += weight * it->ms;
    min_ms = std::min(min_ms, it->ms);
  }
  const double mean_x = sx / sw, mean_t = st / sw;
  double sxx = 0.0, sxt = 0.0;
  weight = 1.0;
  for (auto it = samples_.rbegin(); it != samples_.rend(); ++it, weight *= kAgeWeight) {
    sxx += weight * (it->work - mean_x) * (it->work - mean_x);
    sxt += weight * (it->work - mean_x) * (it->ms - mean_t);
  }
  const double variance = sxx / sw;
  if (samples_.size() >= 3 && variance > kMinRelativeSpread * kMinRelativeSpread * mean_x * mean_x) {
    const double slope = sxt / sxx;
    if (slope > 0.0) fixed_ms_ = mean_t - slope * mean_x;
  }
  // Never more than the cheapest band measured, never negative.
  fixed_ms_ = std::clamp(fixed_ms_, 0.0, 0.95 * min_ms);
}

}  // namespace cohort::balance
