// The balancer implementations; use make_balancer() to get one.
#pragma once

#include <map>
#include <vector>

#include "affine_time_fit.h"
#include "cohort/balance/balancer.h"
#include "speed_book.h"

namespace cohort::balance {

// What a balancer learns belongs to one image height: a frame of another height starts it over.
// True when it did; `rows_seen` then holds the new height.
inline bool restarted_for_new_height(Balancer& balancer, int& rows_seen, int rows) {
  if (rows == rows_seen) return false;
  balancer.reset();
  rows_seen = rows;
  return true;
}

// Equal rows for everyone, whatever was measured: the baseline.
class NoneBalancer final : public Balancer {
 public:
  std::string name() const override { return "none"; }
  std::vector<Band> divide(const DivideInput& in) override;
  void reset() override {}
};

// Starts equal; every frame moves a fixed number of units from the tracer that took longest to the
// one that finished first (Brigade, §4.4).
class RobinHoodBalancer final : public Balancer {
 public:
  explicit RobinHoodBalancer(int units_per_frame) : step_(units_per_frame < 1 ? 1 : units_per_frame) {}
  std::string name() const override { return "robin-hood"; }
  std::vector<Band> divide(const DivideInput& in) override;
  void reset() override { units_.clear(); rows_ = -1; }

 private:
  int step_;
  int rows_ = -1;
  std::map<int, int> units_;  // tracer id -> units it holds
};

// Rows proportional to measured speed (rows/ms) of the previous frame (eq. 1), optionally blended with
// the previous division: W = (1 - alpha) * W_prev + alpha * W_perfect (eq. 2, "Perfect Smooth").
class PerfectBalancer final : public Balancer {
 public:
  PerfectBalancer(double alpha, bool smooth) : alpha_(alpha), smooth_(smooth) {}
  std::string name() const override { return smooth_ ? "perfect-smooth" : "perfect"; }
  std::vector<Band> divide(const DivideInput& in) override;
  void reset() override { speeds_.clear(); last_rows_.clear(); rows_ = -1; }

 private:
  double alpha_;
  bool smooth_;
  int rows_ = -1;
  SpeedBook speeds_;
  std::map<int, double> last_rows_;  // tracer id -> rows it was given last frame (Perfect Smooth's memory)
};

// Cohort's own scheme. Perfect assumes every row costs the same, so a band over an expensive part of
// the image makes its tracer look slow and it is starved next frame (and the reverse): Perfect
// oscillates and Perfect Smooth lags. Row Cost separates the two causes: it keeps a cost per work
// unit (what the view makes expensive, shared by all tracers) and a speed per tracer (what the
// hardware does, slowly varying), and cuts so that predicted time (band cost / speed) is equal for
// every tracer. With a per-row work proxy (e.g. rays counted per row last frame) the map is the proxy
// and speeds are measured directly as work per ms; without one, each tracer's measured time re-scales
// the cost of the units it rendered and the map's shape is learnt as the cuts move.
class RowCostBalancer final : public Balancer {
 public:
  RowCostBalancer(double cost_rate, double speed_rate) : cost_rate_(cost_rate), speed_rate_(speed_rate) {}
  std::string name() const override { return "row-cost"; }
  std::vector<Band> divide(const DivideInput& in) override;
  void reset() override { cost_.clear(); speed_.clear(); rows_ = -1; proxy_mode_ = false; }

  const std::vector<double>& unit_costs() const { return cost_; }

 private:
  void learn_from_proxy(const DivideInput& in, const std::vector<double>& proxy);
  void learn_from_times(const DivideInput& in);
  std::vector<double> unit_proxy(const DivideInput& in) const;

  double cost_rate_;
  double speed_rate_;
  int rows_ = -1;
  std::vector<double> cost_;      // per work unit, mean 1
  std::map<int, double> speed_;   // tracer id -> cost units per ms
  bool proxy_mode_ = false;       // costs and speeds are in the proxy's work units
};

// Balancing that sees the whole cost of a band: each tracer's time is fit as fixed + work x cost
// (AffineTimeFit, from every band it rendered, commit apply included), and the frame is cut so that
// every tracer taking part is predicted to finish at the same time. Work is the per-row work proxy
// when there is one (as Row Cost), else rows. A tracer whose fixed cost leaves it nothing useful to do
// -- the frame is predicted less than min_gain faster with it than without -- gets no rows (it is
// benched: it still applies every commit) and is probed with a small unwaited band every
// probe_interval frames, alternating two sizes so that its fit separates fixed from per-row cost.
// Small bands are cut on single rows (fine_cuts), large ones on the paper's 4-row units.
class WholeCostBalancer final : public Balancer {
 public:
  explicit WholeCostBalancer(const BalancerOptions& options) : options_(options) {}
  std::string name() const override { return "whole-cost"; }
  std::vector<Band> divide(const DivideInput& in) override;
  BandRules band_rules() const override { return {options_.fine_cuts ? 1 : kRowsPerUnit, true}; }
  std::vector<Band> probe_bands() const override { return probes_; }
  void reset() override {
    fits_.clear();
    benched_.clear();
    probes_.clear();
    rows_ = -1;
    proxy_mode_ = false;
  }

 private:
  struct Benched {
    int frames = 0;    // since it was benched or last probed
    int probes = 0;    // probes sent, to alternate their size
  };
  // Prefix sums of the per-row work map of this frame: work of rows [0, r) is prefix[r].
  std::vector<double> work_prefix(const DivideInput& in, bool& from_proxy) const;
  std::vector<bool> choose_takers(const std::vector<double>& fixed, const std::vector<double>& cost, double total_work) const;
  std::vector<Band> cut(const std::vector<double>& prefix, const std::vector<double>& shares, int rows) const;

  BalancerOptions options_;
  int rows_ = -1;
  bool proxy_mode_ = false;
  std::map<int, AffineTimeFit> fits_;
  std::map<int, Benched> benched_;
  std::vector<Band> probes_;
};

}  // namespace cohort::balance
