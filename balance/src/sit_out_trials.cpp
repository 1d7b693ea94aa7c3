#include "sit_out_trials.h"

#include <algorithm>
#include <cmath>

#include "cohort/balance/order_statistics.h"

namespace cohort::balance {

std::vector<Band> without_bands(const std::vector<Band>& bands, const std::vector<bool>& drop, int rows, int row_unit) {
  const int unit = std::max(row_unit, 1);
  double kept_rows = 0.0;
  int kept = 0;
  for (size_t i = 0; i < bands.size(); ++i)
    if (!drop[i] && !bands[i].empty()) kept_rows += bands[i].rows(), ++kept;
  if (kept == 0) return bands;
  std::vector<Band> out(bands.size());
  int at = 0, left = kept;
  double running = 0.0;
  for (size_t i = 0; i < bands.size(); ++i) {
    if (drop[i] || bands[i].empty()) {
      out[i] = Band{at, at};
      continue;
    }
    running += bands[i].rows();
    --left;
    int end = rows;
    if (left > 0) {
      end = static_cast<int>(std::lround(running * rows / kept_rows / unit)) * unit;
      end = std::clamp(end, std::min(at + unit, rows), std::max(rows - left * unit, at));
    }
    out[i] = Band{at, end};
    at = end;
  }
  return out;
}

SitOutTrials::SitOutTrials(std::unique_ptr<Balancer> inner, const BalancerOptions& options)
    : inner_(std::move(inner)), options_(options) {}

BandRules SitOutTrials::band_rules() const {
  BandRules rules = inner_->band_rules();
  rules.allow_empty = true;
  return rules;
}

std::vector<SitOutVerdict> SitOutTrials::take_verdicts() {
  std::vector<SitOutVerdict> out;
  out.swap(verdicts_);
  return out;
}

void SitOutTrials::forget_state() {
  frames_ = 0;
  trial_.reset();
  counted_window_frame_ = -1;
  sitting_out_.clear();
  next_trial_at_.clear();
  small_for_.clear();
  probes_.clear();
}

void SitOutTrials::reset() {
  inner_->reset();
  forget_state();
  rows_ = -1;
}

void SitOutTrials::record_interval(double interval_ms) {
  // The interval that ends now is the previous frame's; the first frames of a window still carry the
  // other mode's work through the pipeline and are not counted.
  if (!trial_ || counted_window_frame_ < options_.trial_settle) return;
  if (!(interval_ms > 0.0) || !std::isfinite(interval_ms)) return;
  (previous_without_ ? trial_->without : trial_->with).push_back(interval_ms);
}

void SitOutTrials::finish_trial() {
  const Trial& t = *trial_;
  SitOutVerdict v;
  v.tracer = t.tracer;
  v.with_ms = median(t.with);
  v.without_ms = median(t.without);
  v.frames_each = static_cast<int>(std::min(t.with.size(), t.without.size()));
  // It keeps its rows only when frames are measurably faster with it.
  v.sits_out = !(v.frames_each > 0 && v.with_ms < v.without_ms * (1.0 - options_.trial_min_gain));
  v.next_trial_in = options_.trial_every;
  if (v.sits_out) sitting_out_.insert(t.tracer);
  else sitting_out_.erase(t.tracer);
  next_trial_at_[t.tracer] = frames_ + options_.trial_every;
  verdicts_.push_back(v);
  trial_.reset();
}

void SitOutTrials::start_trial_if_due(const DivideInput& in, const std::vector<Band>& bands) {
  int takers = 0;
  for (const Band& b : bands) takers += !b.empty();
  // A small taker: at most trial_share of the frame and half an even share (four GPUs' quarters are not
  // tried beside a CPU tracer's sliver), for a whole trial window in a row: a share that dips for a frame or
  // two while the split settles (a band that ended late, a hiccup) is no reason to try a tracer out.
  for (size_t i = 0; i < in.tracers.size(); ++i) {
    const bool small = takers >= 2 && !bands[i].empty() && bands[i].rows() <= options_.trial_share * in.rows &&
                       bands[i].rows() <= 0.5 * in.rows / takers;
    int& run = small_for_[in.tracers[i]];
    run = small ? run + 1 : 0;
  }
  if (trial_ || frames_ < options_.trial_warmup || takers < 2) return;
  for (size_t i = 0; i < in.tracers.size(); ++i) {
    const int id = in.tracers[i];
    auto due = next_trial_at_.find(id);
    if (due != next_trial_at_.end() && frames_ < due->second) continue;
    // Out by verdict and due again: back in; the inner balancer's band says whether it is a candidate.
    sitting_out_.erase(id);
    if (small_for_[id] < std::max(options_.trial_window, 1)) continue;
    trial_ = Trial{id, 0, {}, {}};
    return;
  }
}

std::vector<Band> SitOutTrials::divide(const DivideInput& in) {
  std::vector<Band> bands = inner_->divide(in);
  probes_ = inner_->probe_bands();
  const size_t count = in.tracers.size();
  if (probes_.size() != count) probes_.assign(count, Band{});
  if (in.rows != rows_) {
    forget_state();
    rows_ = in.rows;
  }
  if (!options_.frame_trials) return bands;
  // Trials run on measured intervals only: with none (a virtual clock), the inner division stands.
  if (!(in.last_interval_ms > 0.0)) {
    trial_.reset();
    counted_window_frame_ = -1;
    sitting_out_.clear();
    return bands;
  }
  record_interval(in.last_interval_ms);
  ++frames_;
  if (trial_ && std::find(in.tracers.begin(), in.tracers.end(), trial_->tracer) == in.tracers.end()) {
    next_trial_at_[trial_->tracer] = frames_ + options_.trial_window;  // it left (busy, failed): later
    trial_.reset();
  }
  if (trial_ && trial_->frame >= 2 * options_.trial_window * options_.trial_pairs) finish_trial();
  start_trial_if_due(in, bands);

  std::vector<bool> drop(count, false);
  for (size_t i = 0; i < count; ++i) drop[i] = sitting_out_.count(in.tracers[i]) != 0;
  counted_window_frame_ = -1;
  if (trial_) {
    const int window = std::max(options_.trial_window, 1);
    counted_window_frame_ = trial_->frame % window;
    previous_without_ = (trial_->frame / window) % 2 == 1;
    for (size_t i = 0; i < count; ++i)
      if (in.tracers[i] == trial_->tracer) drop[i] = previous_without_;
    ++trial_->frame;
  }
  if (std::none_of(drop.begin(), drop.end(), [](bool d) { return d; })) return bands;
  for (size_t i = 0; i < count; ++i)
    if (drop[i]) probes_[i] = Band{};
  return without_bands(bands, drop, in.rows, inner_->band_rules().row_unit);
}

}  // namespace cohort::balance
