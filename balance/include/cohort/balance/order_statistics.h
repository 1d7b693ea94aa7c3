// Order statistics of measured times, defined once for the balancer's sit-out trials, the benchmarks and
// `cohort play --frames`: the q-quantile interpolated linearly between the two nearest ranks (Hyndman and
// Fan's type 7, numpy's default), so the median of an even count is the mean of the middle two.
#pragma once

#include <algorithm>
#include <vector>

namespace cohort {

// q in [0, 1]; 0 for no values.
inline double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double at = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(at);
  const size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (at - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

inline double median(std::vector<double> values) { return quantile(std::move(values), 0.5); }

}  // namespace cohort
