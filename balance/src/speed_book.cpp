#include "speed_book.h"

#include <cmath>

namespace cohort::balance {

void SpeedBook::update(const std::vector<TracerMeasurement>& measurements) {
  for (const TracerMeasurement& m : measurements) {
    if (m.ms > 0.0 && std::isfinite(m.ms) && m.band.rows() > 0) speed_[m.tracer] = m.band.rows() / m.ms;
  }
}

std::vector<double> SpeedBook::speeds_for(const std::vector<int>& tracers) const {
  double sum = 0.0;
  int known = 0;
  for (int id : tracers) {
    if (auto it = speed_.find(id); it != speed_.end()) {
      sum += it->second;
      ++known;
    }
  }
  const double fallback = known > 0 ? sum / known : 1.0;
  std::vector<double> speeds;
  speeds.reserve(tracers.size());
  for (int id : tracers) {
    auto it = speed_.find(id);
    speeds.push_back(it != speed_.end() ? it->second : fallback);
  }
  return speeds;
}

std::vector<double> previous_rows(const std::vector<int>& tracers, const std::vector<TracerMeasurement>& measurements) {
  std::vector<double> rows(tracers.size(), 0.0);
  for (size_t i = 0; i < tracers.size(); ++i) {
    for (const TracerMeasurement& m : measurements) {
      if (m.tracer == tracers[i]) rows[i] = m.band.rows();
    }
  }
  return rows;
}

}  // namespace cohort::balance
