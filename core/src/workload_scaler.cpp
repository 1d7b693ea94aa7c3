#include "cohort/core/workload_scaler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace cohort::core {

WorkloadScaler::WorkloadScaler(WorkloadScalerOptions options, WorkloadSetting start) : options_(options), setting_(start) {
  if (!(options_.target_ms > 0.0)) throw std::invalid_argument("WorkloadScaler: target_ms must be > 0");
  if (options_.min_spp < 1 || options_.max_spp < options_.min_spp)
    throw std::invalid_argument("WorkloadScaler: need 1 <= min_spp <= max_spp");
  if (!(options_.min_scale > 0.0 && options_.min_scale <= 1.0)) throw std::invalid_argument("WorkloadScaler: min_scale must be in (0, 1]");
  options_.tolerance = std::clamp(options_.tolerance, 0.01, 0.9);
  options_.smoothing = std::clamp(options_.smoothing, 0.01, 1.0);
  setting_.spp = std::clamp(setting_.spp, options_.min_spp, options_.max_spp);
  setting_.render_scale = options_.scale_resolution ? std::clamp(setting_.render_scale, options_.min_scale, 1.0) : 1.0;
}

// Lighter setting for a frame that takes too long: as much spp as fits the target; once spp is at
// its minimum, lower the render scale.
WorkloadSetting WorkloadScaler::faster(double ms_per_work) const {
  WorkloadSetting next = setting_;
  const double scale2 = next.render_scale * next.render_scale;
  const int fitting = static_cast<int>(std::floor(options_.target_ms / (ms_per_work * scale2)));
  next.spp = std::clamp(std::min(fitting, setting_.spp - 1), options_.min_spp, options_.max_spp);
  if (next.spp == setting_.spp && options_.scale_resolution) {
    const double fitting_scale = std::sqrt(options_.target_ms / (ms_per_work * next.spp));
    next.render_scale = std::clamp(std::min(fitting_scale, setting_.render_scale - options_.scale_step), options_.min_scale, 1.0);
  }
  return next;
}

// Heavier setting for a frame with time to spare: first back to full resolution, then more spp, but
// only as far as the predicted time stays under the band's upper edge.
WorkloadSetting WorkloadScaler::slower(double ms_per_work) const {
  const double ceiling = options_.target_ms * (1.0 + options_.tolerance);
  const double aim = options_.target_ms;
  WorkloadSetting next = setting_;
  if (options_.scale_resolution && next.render_scale < 1.0) {
    // Aimed at the target, so the prediction is inside the band by construction.
    next.render_scale = std::clamp(std::sqrt(aim / (ms_per_work * next.spp)), setting_.render_scale, 1.0);
    return next;
  }
  const int fitting = static_cast<int>(std::floor(aim / (ms_per_work * next.render_scale * next.render_scale)));
  next.spp = std::clamp(std::max(fitting, setting_.spp), options_.min_spp, options_.max_spp);
  if (next.spp > setting_.spp && work(next) * ms_per_work > ceiling) next.spp = setting_.spp;
  return next;
}

void WorkloadScaler::change_to(const WorkloadSetting& next) {
  if (next == setting_) return;
  // Predict the new time so the running mean does not have to re-learn from scratch.
  smoothed_ms_ *= work(next) / work(setting_);
  setting_ = next;
  over_ = under_ = 0;
}

WorkloadSetting WorkloadScaler::update(double frame_ms) {
  if (!(frame_ms > 0.0) || !std::isfinite(frame_ms)) return setting_;
  smoothed_ms_ = have_time_ ? (1.0 - options_.smoothing) * smoothed_ms_ + options_.smoothing * frame_ms : frame_ms;
  have_time_ = true;
  const double ms_per_work = smoothed_ms_ / work(setting_);
  if (smoothed_ms_ > options_.target_ms * (1.0 + options_.tolerance)) {
    under_ = 0;
    if (++over_ >= options_.patience) change_to(faster(ms_per_work));
  } else if (smoothed_ms_ < options_.target_ms * (1.0 - options_.tolerance)) {
    over_ = 0;
    if (++under_ >= options_.patience) change_to(slower(ms_per_work));
  } else {
    over_ = under_ = 0;
  }
  return setting_;
}

}  // namespace cohort::core
