#include <numeric>

#include "balancers.h"

namespace cohort::balance {

std::vector<Band> PerfectBalancer::divide(const DivideInput& in) {
  const size_t count = in.tracers.size();
  if (count == 0) return {};
  restarted_for_new_height(*this, rows_, in.rows);
  speeds_.update(in.previous);
  // Eq. 1: W_i = R * s_i / sum_j s_j with s_i = rows_i / t_i from the previous frame.
  const std::vector<double> speeds = speeds_.speeds_for(in.tracers);
  const double speed_sum = std::accumulate(speeds.begin(), speeds.end(), 0.0);
  std::vector<double> rows(count);
  for (size_t i = 0; i < count; ++i) rows[i] = in.rows * speeds[i] / speed_sum;

  if (smooth_) {
    // Eq. 2: blend with what each tracer had last frame. A tracer with no previous share (new, or
    // back after an absence) starts from its Perfect share; shares are renormalised by the cut.
    for (size_t i = 0; i < count; ++i) {
      auto it = last_rows_.find(in.tracers[i]);
      if (it != last_rows_.end()) rows[i] = (1.0 - alpha_) * it->second + alpha_ * rows[i];
    }
  }
  std::vector<Band> bands = bands_from_shares(in.rows, rows);
  // Remember the unrounded blend, not the unit-rounded band: rounding every frame would stall eq. 2
  // whenever the correction is below half a unit.
  const double total = std::accumulate(rows.begin(), rows.end(), 0.0);
  last_rows_.clear();
  for (size_t i = 0; i < count; ++i) last_rows_[in.tracers[i]] = total > 0 ? rows[i] * in.rows / total : 0.0;
  return bands;
}

}  // namespace cohort::balance
