// Row bands: the slice of a frame each tracer renders. The frame is cut into work units of
// kRowsPerUnit rows (Brigade, §4.3); every band starts on a unit boundary, so every band is a whole
// number of units except the last, which ends at the frame's last row.
#pragma once

#include <span>
#include <string>
#include <vector>

namespace cohort::balance {

constexpr int kRowsPerUnit = 4;

struct Band {
  int begin = 0;  // first row
  int end = 0;    // one past the last row
  int rows() const { return end - begin; }
  bool empty() const { return end <= begin; }
  friend bool operator==(const Band&, const Band&) = default;
};

// Units needed to cover `rows` rows (the last one may be partial).
int units_for_rows(int rows);

// Contiguous bands covering rows [0, rows), one per share, in order; band i gets about
// shares[i] / sum(shares) of the units. Every band gets at least one unit while there are at least
// as many units as bands (with fewer units, trailing bands are empty). Non-finite or negative
// shares count as zero; all-zero shares give an equal split.
std::vector<Band> bands_from_shares(int rows, std::span<const double> shares);

// Same, but the cut after band i is placed at cumulative_units[i] (fractional units, ascending,
// last one == total units); cuts are rounded to the nearest unit and kept >= 1 unit apart.
std::vector<Band> bands_from_cuts(int rows, std::span<const double> cumulative_units);

// Equal split.
std::vector<Band> equal_bands(int rows, int count);

// What a division may look like. The paper's rules (the default): cuts on kRowsPerUnit boundaries and
// every band non-empty while units allow. A balancer that benches tracers or cuts finer relaxes them.
struct BandRules {
  int row_unit = kRowsPerUnit;  // cuts fall on multiples of this (the last band ends at the frame's end)
  bool allow_empty = false;     // a band may be empty (its tracer gets no rows); one band at least is not
};

// Empty when `bands` is a valid division of `rows` rows under `rules` (contiguous, covering, cuts on
// the rules' boundaries, non-empty as the rules ask); otherwise says what is wrong.
std::string check_bands(int rows, std::span<const Band> bands, const BandRules& rules = {});

}  // namespace cohort::balance
