// What the benchmark charts (bench balance, bench devices, bench_scaling) share: their colours, text
// size and axis numbers, so that the charts look alike.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include "raster/image.h"

namespace cohort::raster::chart {

inline const Rgba8 kBackground{255, 255, 255}, kInk{30, 30, 30}, kGrid{225, 225, 225};
constexpr int kTextScale = 2;  // font pixels drawn 2x2: labels readable on a chart this size

// Whole numbers without decimals, others with one.
inline std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, v == std::floor(v) ? "%.0f" : "%.1f", v);
  return buf;
}

// A round axis maximum at or above v: 1, 2, 5 x 10^k.
inline double nice_ceiling(double v) {
  if (!(v > 0.0)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= v) return m * p;
  return 10.0 * p;
}

}  // namespace cohort::raster::chart
