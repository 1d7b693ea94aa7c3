#include <algorithm>
#include <cmath>
#include <numeric>

#include "balancers.h"

namespace cohort::balance {
namespace {

struct UnitRange {
  int begin, end;
};

UnitRange units_of(const Band& band, int units) {
  const int begin = std::clamp(band.begin / kRowsPerUnit, 0, units);
  const int end = std::clamp(units_for_rows(band.end), begin, units);
  return {begin, end};
}

double sum_over(const std::vector<double>& values, UnitRange r) {
  return std::accumulate(values.begin() + r.begin, values.begin() + r.end, 0.0);
}

}  // namespace

std::vector<double> RowCostBalancer::unit_proxy(const DivideInput& in) const {
  if (static_cast<int>(in.row_cost_proxy.size()) != in.rows || in.rows <= 0) return {};
  std::vector<double> proxy(cost_.size(), 0.0);
  double total = 0.0;
  for (int row = 0; row < in.rows; ++row) {
    const double v = in.row_cost_proxy[static_cast<size_t>(row)];
    if (std::isfinite(v) && v > 0.0) {
      proxy[static_cast<size_t>(row / kRowsPerUnit)] += v;
      total += v;
    }
  }
  if (total <= 0.0) return {};
  // A floor keeps a unit the proxy calls free from being predicted free: rays still cost something.
  const double floor = 0.05 * total / static_cast<double>(proxy.size());
  for (double& p : proxy) p = std::max(p, floor);
  return proxy;
}

void RowCostBalancer::learn_from_proxy(const DivideInput& in, const std::vector<double>& proxy) {
  // The proxy counts the work of the very frame whose times we hold, so each tracer's speed (work per
  // ms) is measured directly; the map is simply the proxy. Speeds are hardware properties: smoothing
  // them over frames cancels the timing noise without lagging behind the view.
  const int units = static_cast<int>(proxy.size());
  for (const TracerMeasurement& m : in.previous) {
    if (!(m.ms > 0.0) || !std::isfinite(m.ms) || m.band.rows() <= 0) continue;
    const UnitRange r = units_of(m.band, units);
    const double work = sum_over(proxy, r);
    if (!(work > 0.0)) continue;
    const double observed = work / m.ms;
    auto it = speed_.find(m.tracer);
    speed_[m.tracer] = it == speed_.end() ? observed : (1.0 - speed_rate_) * it->second + speed_rate_ * observed;
  }
  cost_ = proxy;
}

void RowCostBalancer::learn_from_times(const DivideInput& in) {
  const int units = static_cast<int>(cost_.size());
  std::vector<double> updated = cost_;
  for (const TracerMeasurement& m : in.previous) {
    if (!(m.ms > 0.0) || !std::isfinite(m.ms) || m.band.rows() <= 0) continue;
    const UnitRange r = units_of(m.band, units);
    if (r.end <= r.begin) continue;
    const double predicted_cost = sum_over(cost_, r);
    const double observed_speed = predicted_cost / m.ms;
    auto it = speed_.find(m.tracer);
    // A tracer seen for the first time is taken at its word (as Perfect would); afterwards its speed
    // moves slowly, so that a band turning expensive shows up as cost, not as a slower tracer.
    const double speed = it == speed_.end() ? observed_speed : (1.0 - speed_rate_) * it->second + speed_rate_ * observed_speed;
    speed_[m.tracer] = speed;
    // The band's measured cost is spread evenly over its units (one time says nothing about where
    // in the band it went) and blended into the map, which keeps older detail: rows that change
    // hands carry the cost they showed in their previous band, not the receiving band's average,
    // as Perfect assumes. (Keeping the old shape inside the band instead was measured worse: it is
    // stale as soon as the view turns.)
    const double band_cost = m.ms * speed;
    if (!(predicted_cost > 0.0)) continue;
    const double measured = band_cost / (r.end - r.begin);
    for (int u = r.begin; u < r.end; ++u) {
      updated[static_cast<size_t>(u)] = (1.0 - cost_rate_) * cost_[static_cast<size_t>(u)] + cost_rate_ * measured;
    }
  }
  // Keep the map's mean at 1 so it cannot drift; speeds are in the same units, so they scale along.
  const double mean = std::accumulate(updated.begin(), updated.end(), 0.0) / units;
  if (mean > 0.0 && std::isfinite(mean)) {
    for (double& c : updated) c /= mean;
    for (auto& [id, s] : speed_) s /= mean;
    cost_ = std::move(updated);
  }
}

std::vector<Band> RowCostBalancer::divide(const DivideInput& in) {
  const size_t count = in.tracers.size();
  if (count == 0) return {};
  if (restarted_for_new_height(*this, rows_, in.rows)) cost_.assign(static_cast<size_t>(units_for_rows(in.rows)), 1.0);
  // With a proxy, speeds are in its work units; without, in units of the normalised map. Switching
  // between the two starts the speeds over.
  const std::vector<double> proxy = unit_proxy(in);
  if (proxy.empty() == proxy_mode_) {
    speed_.clear();
    proxy_mode_ = !proxy.empty();
    if (!proxy_mode_) cost_.assign(static_cast<size_t>(units_for_rows(in.rows)), 1.0);
  }
  if (proxy_mode_) learn_from_proxy(in, proxy);
  else learn_from_times(in);

  // Speeds of this frame's tracers; a newcomer is assumed average.
  std::vector<double> speeds(count, 0.0);
  double known_sum = 0.0;
  int known = 0;
  for (size_t i = 0; i < count; ++i) {
    if (auto it = speed_.find(in.tracers[i]); it != speed_.end()) {
      speeds[i] = it->second;
      known_sum += it->second;
      ++known;
    }
  }
  for (size_t i = 0; i < count; ++i) {
    if (!speed_.count(in.tracers[i])) speeds[i] = known > 0 ? known_sum / known : 1.0;
  }
  const double speed_sum = std::accumulate(speeds.begin(), speeds.end(), 0.0);

  // Cut where the running cost reaches each tracer's share of the total (equal predicted time),
  // interpolating inside a unit so rounding picks the nearer boundary.
  const double total_cost = std::accumulate(cost_.begin(), cost_.end(), 0.0);
  std::vector<double> cuts(count);
  double target = 0.0, running = 0.0;
  size_t unit = 0;
  for (size_t i = 0; i < count; ++i) {
    target += total_cost * speeds[i] / speed_sum;
    while (unit < cost_.size() && running + cost_[unit] <= target) running += cost_[unit++];
    const double inside = unit < cost_.size() && cost_[unit] > 0.0 ? (target - running) / cost_[unit] : 0.0;
    cuts[i] = static_cast<double>(unit) + std::clamp(inside, 0.0, 1.0);
  }
  cuts.back() = static_cast<double>(cost_.size());
  return bands_from_cuts(in.rows, cuts);
}

}  // namespace cohort::balance
