#include "cohort/balance/bands.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace cohort::balance {

int units_for_rows(int rows) { return rows <= 0 ? 0 : (rows + kRowsPerUnit - 1) / kRowsPerUnit; }

std::vector<Band> bands_from_cuts(int rows, std::span<const double> cumulative_units) {
  const int count = static_cast<int>(cumulative_units.size());
  std::vector<Band> bands(static_cast<size_t>(count));
  if (count == 0) return bands;
  const int units = units_for_rows(rows);
  // Cut positions in whole units; the first `min(count, units)` bands get >= 1 unit each.
  const int nonempty = std::min(count, units);
  std::vector<int> cut(static_cast<size_t>(count));
  int previous = 0;
  for (int i = 0; i < count; ++i) {
    double wanted = cumulative_units[static_cast<size_t>(i)];
    if (!std::isfinite(wanted)) wanted = previous;
    int c = static_cast<int>(std::lround(std::clamp(wanted, 0.0, static_cast<double>(units))));
    const int lowest = i < nonempty ? previous + 1 : previous;         // this band keeps >= 1 unit
    const int highest = units - std::max(0, nonempty - (i + 1));        // later bands keep >= 1 unit each
    c = std::clamp(c, lowest, highest);
    if (i == count - 1) c = units;
    cut[static_cast<size_t>(i)] = c;
    previous = c;
  }
  int begin_unit = 0;
  for (int i = 0; i < count; ++i) {
    const int end_unit = cut[static_cast<size_t>(i)];
    bands[static_cast<size_t>(i)] = Band{std::min(begin_unit * kRowsPerUnit, rows), std::min(end_unit * kRowsPerUnit, rows)};
    begin_unit = end_unit;
  }
  return bands;
}

std::vector<Band> bands_from_shares(int rows, std::span<const double> shares) {
  const size_t count = shares.size();
  std::vector<double> clean(count);
  for (size_t i = 0; i < count; ++i) clean[i] = std::isfinite(shares[i]) && shares[i] > 0.0 ? shares[i] : 0.0;
  double total = std::accumulate(clean.begin(), clean.end(), 0.0);
  if (total <= 0.0) {
    std::fill(clean.begin(), clean.end(), 1.0);
    total = static_cast<double>(count);
  }
  const double units = units_for_rows(rows);
  std::vector<double> cuts(count);
  double running = 0.0;
  for (size_t i = 0; i < count; ++i) {
    running += clean[i];
    cuts[i] = units * running / total;
  }
  return bands_from_cuts(rows, cuts);
}

std::vector<Band> equal_bands(int rows, int count) {
  std::vector<double> shares(static_cast<size_t>(std::max(count, 0)), 1.0);
  return bands_from_shares(rows, shares);
}

std::string check_bands(int rows, std::span<const Band> bands, const BandRules& rules) {
  if (bands.empty()) return rows > 0 ? "no bands" : "";
  if (rules.row_unit < 1) return "row unit " + std::to_string(rules.row_unit) + " is not positive";
  const int units = rules.allow_empty ? 0 : (rows + rules.row_unit - 1) / rules.row_unit;
  bool any_rows = false;
  int expected_begin = 0;
  for (size_t i = 0; i < bands.size(); ++i) {
    const Band& b = bands[i];
    const std::string where = "band " + std::to_string(i) + " [" + std::to_string(b.begin) + "," + std::to_string(b.end) + ")";
    if (b.begin != expected_begin) return where + " does not start where the previous ended (" + std::to_string(expected_begin) + ")";
    if (b.end < b.begin) return where + " is reversed";
    if (b.end != rows && b.end % rules.row_unit != 0) return where + " does not end on a unit boundary";
    if (b.empty() && static_cast<int>(i) < units) return where + " is empty although there are enough units";
    any_rows = any_rows || !b.empty();
    expected_begin = b.end;
  }
  if (rows > 0 && !any_rows) return "every band is empty";
  if (expected_begin != rows) return "bands end at row " + std::to_string(expected_begin) + ", frame has " + std::to_string(rows);
  return "";
}

}  // namespace cohort::balance
