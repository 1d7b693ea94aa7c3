#include <algorithm>
#include <cmath>

#include "balancers.h"

namespace cohort::balance {

std::vector<Band> RobinHoodBalancer::divide(const DivideInput& in) {
  const int count = static_cast<int>(in.tracers.size());
  if (count == 0) return {};
  restarted_for_new_height(*this, rows_, in.rows);
  // Tracers that left give their units back; newcomers start with the mean holding; then rescale to
  // the frame's unit count.
  std::map<int, int> kept;
  double known_sum = 0.0;
  int known = 0;
  for (int id : in.tracers) {
    if (auto it = units_.find(id); it != units_.end()) {
      kept[id] = it->second;
      known_sum += it->second;
      ++known;
    }
  }
  const double newcomer = known > 0 ? known_sum / known : static_cast<double>(units_for_rows(in.rows)) / count;
  std::vector<double> holding;
  for (int id : in.tracers) holding.push_back(kept.count(id) ? kept[id] : newcomer);

  // Take from the tracer that took longest, give to the one that finished first (measured ones only).
  int slowest = -1, fastest = -1;
  double slowest_ms = 0.0, fastest_ms = 0.0;
  for (int i = 0; i < count; ++i) {
    for (const TracerMeasurement& m : in.previous) {
      if (m.tracer != in.tracers[static_cast<size_t>(i)] || !(m.ms > 0.0) || !std::isfinite(m.ms)) continue;
      if (slowest < 0 || m.ms > slowest_ms) { slowest = i; slowest_ms = m.ms; }
      if (fastest < 0 || m.ms < fastest_ms) { fastest = i; fastest_ms = m.ms; }
    }
  }
  std::vector<Band> bands = bands_from_shares(in.rows, holding);
  std::vector<int> unit_counts;
  for (const Band& b : bands) unit_counts.push_back(units_for_rows(b.rows()));
  if (slowest >= 0 && fastest >= 0 && slowest != fastest) {
    const int moved = std::clamp(unit_counts[static_cast<size_t>(slowest)] - 1, 0, step_);
    unit_counts[static_cast<size_t>(slowest)] -= moved;
    unit_counts[static_cast<size_t>(fastest)] += moved;
  }
  std::vector<double> cuts;
  double running = 0.0;
  for (int c : unit_counts) cuts.push_back(running += c);
  bands = bands_from_cuts(in.rows, cuts);
  units_.clear();
  for (int i = 0; i < count; ++i) units_[in.tracers[static_cast<size_t>(i)]] = units_for_rows(bands[static_cast<size_t>(i)].rows());
  return bands;
}

}  // namespace cohort::balance
