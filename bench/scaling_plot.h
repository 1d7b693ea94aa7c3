// The scaling benchmark's chart: lines of y against x on a log2 x axis (lights doubling), drawn with
// the same raster primitives, palette and lettering as the balance chart (bench/balance/balance_plot.cpp).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace cohort::bench {

struct ScalingSeries {
  std::string label;
  std::vector<std::pair<double, double>> points;   // (x > 0, y), in x order
};

// Writes a PNG (or any format core::write_ldr_image takes). Throws std::runtime_error without points.
void write_scaling_plot(const std::string& file, const std::string& title, const std::string& x_label,
                        const std::string& y_label, const std::vector<ScalingSeries>& series);

}  // namespace cohort::bench
