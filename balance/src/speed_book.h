// Per-tracer speeds in rows per millisecond, as Perfect (eq. 1) measures them: rows / time. Remembers
// the last good speed of a tracer that reported no time this frame (dropped, timed out, zero time).
#pragma once

#include <map>
#include <vector>

#include "cohort/balance/balancer.h"

namespace cohort::balance {

class SpeedBook {
 public:
  void update(const std::vector<TracerMeasurement>& measurements);
  // Speeds for `tracers` in order; a tracer never measured gets the mean of the known ones (1 if none).
  std::vector<double> speeds_for(const std::vector<int>& tracers) const;
  void clear() { speed_.clear(); }

 private:
  std::map<int, double> speed_;
};

// The rows each of `tracers` rendered last frame (0 for a tracer not in the measurements).
std::vector<double> previous_rows(const std::vector<int>& tracers, const std::vector<TracerMeasurement>& measurements);

}  // namespace cohort::balance
