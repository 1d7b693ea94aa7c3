#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "cohort/balance/balancer.h"

using namespace cohort::balance;

namespace {

// A frame whose rows cost row_cost[row] each, rendered by tracers of the given speeds.
struct SyntheticFrame {
  std::vector<double> row_cost;
  std::vector<double> speeds;

  std::vector<TracerMeasurement> measure(const std::vector<int>& ids, const std::vector<Band>& bands) const {
    std::vector<TracerMeasurement> out;
    for (size_t i = 0; i < bands.size(); ++i) {
      double cost = 0.0;
      for (int r = bands[i].begin; r < bands[i].end; ++r) cost += row_cost[static_cast<size_t>(r)];
      out.push_back({ids[i], bands[i], cost / speeds[static_cast<size_t>(ids[i])]});
    }
    return out;
  }
};

// Idle share of summed tracer time: sum(max - t_i) / (n * max), the Brigade Table 1 metric.
double idle_fraction(const std::vector<TracerMeasurement>& m) {
  double worst = 0.0, sum = 0.0;
  for (const auto& x : m) { worst = std::max(worst, x.ms); sum += x.ms; }
  return (m.size() * worst - sum) / (m.size() * worst);
}

// Runs `frames` frames and returns the measurements of each.
std::vector<std::vector<TracerMeasurement>> run(Balancer& b, const SyntheticFrame& f, const std::vector<int>& ids, int frames) {
  std::vector<std::vector<TracerMeasurement>> history;
  std::vector<TracerMeasurement> previous;
  const int rows = static_cast<int>(f.row_cost.size());
  for (int i = 0; i < frames; ++i) {
    const auto bands = b.divide({rows, ids, previous, {}});
    EXPECT_EQ(check_bands(rows, bands, b.band_rules()), "") << b.name() << " frame " << i;
    previous = f.measure(ids, bands);
    history.push_back(previous);
  }
  return history;
}

SyntheticFrame uniform(int rows, std::vector<double> speeds) { return {std::vector<double>(static_cast<size_t>(rows), 1.0), std::move(speeds)}; }

}  // namespace

TEST(Balancer, FactoryKnowsEveryNameAndRejectsOthers) {
  for (const std::string& name : balancer_names()) EXPECT_EQ(make_balancer(name)->name(), name);
  try {
    make_balancer("fastest");
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("perfect-smooth"), std::string::npos) << e.what();
  }
  BalancerOptions bad;
  bad.alpha = 0.0;
  EXPECT_THROW(make_balancer("perfect-smooth", bad), std::invalid_argument);
}

TEST(Balancer, NoneSplitsEquallyWhateverWasMeasured) {
  auto b = make_balancer("none");
  const std::vector<TracerMeasurement> prev{{0, {0, 200}, 10.0}, {1, {200, 400}, 1.0}};
  const auto bands = b->divide({400, {0, 1}, prev, {}});
  EXPECT_EQ(bands[0].rows(), 200);
  EXPECT_EQ(bands[1].rows(), 200);
}

TEST(Balancer, PerfectGivesATwiceAsFastTracerTwoThirds) {
  auto b = make_balancer("perfect");
  const std::vector<TracerMeasurement> prev{{0, {0, 360}, 10.0}, {1, {360, 720}, 20.0}};
  const auto bands = b->divide({720, {0, 1}, prev, {}});
  EXPECT_NEAR(bands[0].rows(), 480, kRowsPerUnit);
  EXPECT_NEAR(bands[1].rows(), 240, kRowsPerUnit);
}

TEST(Balancer, PerfectSmoothMovesHalfWayThenConverges) {
  auto b = make_balancer("perfect-smooth");  // alpha 0.5
  const SyntheticFrame f = uniform(720, {2.0, 1.0});
  const auto history = run(*b, f, {0, 1}, 12);
  EXPECT_EQ(history[0][0].band.rows(), 360);               // no measurement yet: equal
  EXPECT_NEAR(history[1][0].band.rows(), 420, kRowsPerUnit);  // half way from 360 to 480
  EXPECT_NEAR(history.back()[0].band.rows(), 480, kRowsPerUnit);
  EXPECT_LT(idle_fraction(history.back()), 0.02);
}

TEST(Balancer, PerfectSmoothAlphaOneIsPerfect) {
  BalancerOptions o;
  o.alpha = 1.0;
  auto smooth = make_balancer("perfect-smooth", o);
  auto perfect = make_balancer("perfect");
  const std::vector<TracerMeasurement> prev{{0, {0, 100}, 3.0}, {1, {100, 300}, 5.0}, {2, {300, 400}, 1.0}};
  EXPECT_EQ(smooth->divide({400, {0, 1, 2}, prev, {}}), perfect->divide({400, {0, 1, 2}, prev, {}}));
}

TEST(Balancer, RobinHoodMovesFixedUnitsFromSlowestToFastest) {
  BalancerOptions o;
  o.robin_hood_units = 3;
  auto b = make_balancer("robin-hood", o);
  const auto first = b->divide({480, {0, 1, 2}, {}, {}});
  EXPECT_EQ(first[0].rows(), 160);
  const std::vector<TracerMeasurement> prev{{0, first[0], 5.0}, {1, first[1], 9.0}, {2, first[2], 2.0}};
  const auto second = b->divide({480, {0, 1, 2}, prev, {}});
  EXPECT_EQ(second[0].rows(), 160);
  EXPECT_EQ(second[1].rows(), 160 - 3 * kRowsPerUnit);
  EXPECT_EQ(second[2].rows(), 160 + 3 * kRowsPerUnit);
}

TEST(Balancer, RobinHoodNeverTakesATracersLastUnit) {
  BalancerOptions o;
  o.robin_hood_units = 50;
  auto b = make_balancer("robin-hood", o);
  const SyntheticFrame f = uniform(64, {1.0, 0.01});
  const auto history = run(*b, f, {0, 1}, 5);
  EXPECT_EQ(history.back()[1].band.rows(), kRowsPerUnit);
}

TEST(Balancer, RowCostBalancesAnUnevenImage) {
  // Equal tracers; the lower half of the image costs four times the upper half. Balanced means
  // equal cost: the top band takes the 360 cheap rows plus 135 of the expensive ones.
  SyntheticFrame f = uniform(720, {1.0, 1.0});
  for (int r = 360; r < 720; ++r) f.row_cost[static_cast<size_t>(r)] = 4.0;
  auto row_cost = make_balancer("row-cost");
  const auto rc = run(*row_cost, f, {0, 1}, 30);
  EXPECT_NEAR(rc.back()[0].band.rows(), 495, 2 * kRowsPerUnit);
  EXPECT_LT(idle_fraction(rc.back()), 0.01);
}

TEST(Balancer, RowCostLearnsUnequalSpeedsOnAUniformImage) {
  auto b = make_balancer("row-cost");
  const auto history = run(*b, uniform(720, {1.0, 0.7, 1.3}), {0, 1, 2}, 40);
  EXPECT_LT(idle_fraction(history.back()), 0.02);
}

TEST(Balancer, RowCostUsesTheImageSpaceProxyToShapeCosts) {
  SyntheticFrame f = uniform(720, {1.0, 1.0});
  for (int r = 0; r < 80; ++r) f.row_cost[static_cast<size_t>(r)] = 10.0;  // an expensive strip at the top
  std::vector<float> proxy(f.row_cost.begin(), f.row_cost.end());
  auto b = make_balancer("row-cost");
  std::vector<TracerMeasurement> previous;
  std::vector<Band> bands;
  for (int i = 0; i < 3; ++i) {
    bands = b->divide({720, {0, 1}, previous, proxy});
    previous = f.measure({0, 1}, bands);
  }
  EXPECT_LT(idle_fraction(previous), 0.02);
}

class EveryBalancer : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryBalancer, ConvergesOnTwoToOneSpeeds) {
  if (GetParam() == "none") GTEST_SKIP() << "none ignores measurements by design";
  auto b = make_balancer(GetParam());
  const auto history = run(*b, uniform(720, {2.0, 1.0}), {0, 1}, GetParam() == "robin-hood" ? 40 : 10);
  EXPECT_NEAR(history.back()[0].band.rows(), 480, 3 * kRowsPerUnit) << GetParam();
}

TEST_P(EveryBalancer, SurvivesZeroTimesNewAndRemovedTracers) {
  auto b = make_balancer(GetParam());
  auto bands = b->divide({100, {0, 1}, {}, {}});
  ASSERT_EQ(check_bands(100, bands, b->band_rules()), "");
  // Tracer 1 reports no time (it was dropped); tracer 7 joins.
  std::vector<TracerMeasurement> prev{{0, bands[0], 4.0}, {1, bands[1], 0.0}};
  bands = b->divide({100, {0, 1, 7}, prev, {}});
  ASSERT_EQ(bands.size(), 3u);
  ASSERT_EQ(check_bands(100, bands, b->band_rules()), "");
  // Tracer 0 leaves; a measurement for it is still in the list and must be ignored for banding.
  prev = {{0, bands[0], 1.0}, {1, bands[1], 3.0}, {7, bands[2], 3.0}};
  bands = b->divide({100, {1, 7}, prev, {}});
  ASSERT_EQ(bands.size(), 2u);
  EXPECT_EQ(check_bands(100, bands, b->band_rules()), "");
  // All zero times, then a resolution change.
  prev = {{1, bands[0], 0.0}, {7, bands[1], 0.0}};
  bands = b->divide({100, {1, 7}, prev, {}});
  EXPECT_EQ(check_bands(100, bands, b->band_rules()), "");
  bands = b->divide({37, {1, 7}, prev, {}});
  EXPECT_EQ(check_bands(37, bands, b->band_rules()), "");
  // A single tracer takes everything; no tracers gives no bands.
  bands = b->divide({37, {7}, {}, {}});
  EXPECT_EQ(bands, (std::vector<Band>{{0, 37}}));
  EXPECT_TRUE(b->divide({37, {}, {}, {}}).empty());
}

INSTANTIATE_TEST_SUITE_P(All, EveryBalancer, ::testing::ValuesIn(balancer_names()),
                         [](const auto& info) {
                           std::string n = info.param;
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n;
                         });

namespace {

// Tracers with a fixed cost per band: ms = fixed + rows * ms_per_row (uniform rows).
struct FixedCostFrame {
  int rows;
  std::vector<double> ms_per_row, fixed_ms;
  double time(int id, const Band& b) const {
    return b.empty() ? 0.0 : fixed_ms[static_cast<size_t>(id)] + b.rows() * ms_per_row[static_cast<size_t>(id)];
  }
};

// Runs whole-cost frames: bands are measured, probes are measured too and reported a frame later,
// as the renderer does. Returns the last frame's bands; `probes` counts the probe bands sent per id.
std::vector<Band> run_whole_cost(Balancer& b, const FixedCostFrame& f, const std::vector<int>& ids, int frames,
                                 std::vector<int>* probes = nullptr, std::vector<TracerMeasurement>* last = nullptr) {
  std::vector<TracerMeasurement> previous, probed;
  std::vector<Band> bands;
  for (int i = 0; i < frames; ++i) {
    bands = b.divide({f.rows, ids, previous, {}});
    EXPECT_EQ(check_bands(f.rows, bands, b.band_rules()), "") << "frame " << i;
    previous = probed;
    probed.clear();
    const std::vector<Band> probe_bands = b.probe_bands();
    for (size_t t = 0; t < ids.size(); ++t) {
      if (!bands[t].empty()) previous.push_back({ids[t], bands[t], f.time(ids[t], bands[t])});
      if (t < probe_bands.size() && !probe_bands[t].empty()) {
        EXPECT_TRUE(bands[t].empty()) << "only a benched tracer is probed";
        probed.push_back({ids[t], probe_bands[t], f.time(ids[t], probe_bands[t])});
        if (probes) ++(*probes)[static_cast<size_t>(ids[t])];
      }
    }
  }
  if (last) *last = previous;
  return bands;
}

double slowest(const std::vector<TracerMeasurement>& m) {
  double worst = 0.0;
  for (const auto& x : m) worst = std::max(worst, x.ms);
  return worst;
}

}  // namespace

TEST(Balancer, WholeCostEqualisesFinishTimesWithAFixedCost) {
  // Equal finish time T: (T - 0) / 0.05 + (T - 3) / 0.1 = 720 rows, so T = 25 ms and the slow tracer
  // gets 220 rows. Perfect, blind to the fixed cost, is biased and keeps oscillating around it.
  const FixedCostFrame f{720, {0.05, 0.1}, {0.0, 3.0}};
  auto b = make_balancer("whole-cost");
  std::vector<TracerMeasurement> last;
  const std::vector<Band> bands = run_whole_cost(*b, f, {0, 1}, 40, nullptr, &last);
  EXPECT_NEAR(bands[1].rows(), 220, 2);
  EXPECT_LT(idle_fraction(last), 0.01);
  EXPECT_NEAR(slowest(last), 25.0, 0.2);
}

TEST(Balancer, WholeCostBenchesATracerThatOnlySlowsTheFrameAndProbesIt) {
  // The fast tracer alone: 720 x 0.006 = 4.3 ms. The slow one (50x slower, 2 ms fixed) could take
  // about 7 rows for a 1 % faster frame: not worth its noise at the frame's end, so it is benched.
  const FixedCostFrame f{720, {0.006, 0.3}, {0.0, 2.0}};
  BalancerOptions options;
  options.probe_interval = 10;
  auto b = make_balancer("whole-cost", options);
  std::vector<int> probes(2, 0);
  std::vector<TracerMeasurement> last;
  const std::vector<Band> bands = run_whole_cost(*b, f, {0, 1}, 60, &probes, &last);
  EXPECT_EQ(bands[0], (Band{0, 720}));
  EXPECT_TRUE(bands[1].empty());
  EXPECT_GE(probes[1], 4) << "probed every " << options.probe_interval << " frames once benched";
  EXPECT_EQ(probes[0], 0);
  EXPECT_NEAR(slowest(last), 720 * 0.006, 1e-9);
}

TEST(Balancer, WholeCostBringsABenchedTracerBackWhenItHelps) {
  // Tracer 1 first looks hopeless (its fixed cost outlasts the frame), then turns fast: the probes
  // see it and it gets rows again.
  FixedCostFrame f{720, {0.006, 0.3}, {0.0, 5.0}};
  BalancerOptions options;
  options.probe_interval = 5;
  auto b = make_balancer("whole-cost", options);
  ASSERT_TRUE(run_whole_cost(*b, f, {0, 1}, 30)[1].empty());
  f.ms_per_row[1] = 0.006;
  f.fixed_ms[1] = 0.1;
  std::vector<TracerMeasurement> last;
  const std::vector<Band> bands = run_whole_cost(*b, f, {0, 1}, 40, nullptr, &last);
  EXPECT_NEAR(bands[1].rows(), 352, 16);
  EXPECT_LT(idle_fraction(last), 0.03);
}

TEST(Balancer, WholeCostCutsSmallSharesFinerThanAUnitUnlessAskedNotTo) {
  // A tracer 100x slower with no fixed cost is worth about 7 rows (min_gain 0: take any gain).
  const FixedCostFrame f{720, {0.01, 1.0}, {0.0, 0.0}};
  BalancerOptions options;
  options.min_gain = 0.0;
  auto fine = make_balancer("whole-cost", options);
  const int fine_rows = run_whole_cost(*fine, f, {0, 1}, 20)[1].rows();
  EXPECT_EQ(fine_rows, 7);
  options.fine_cuts = false;
  auto coarse = make_balancer("whole-cost", options);
  EXPECT_EQ(run_whole_cost(*coarse, f, {0, 1}, 20)[1].rows() % kRowsPerUnit, 0);
  EXPECT_EQ(coarse->band_rules().row_unit, kRowsPerUnit);
}

TEST(Balancer, WholeCostRejectsBadOptions) {
  BalancerOptions bad;
  bad.min_gain = 1.0;
  EXPECT_THROW(make_balancer("whole-cost", bad), std::invalid_argument);
  bad = {};
  bad.probe_interval = 0;
  EXPECT_THROW(make_balancer("whole-cost", bad), std::invalid_argument);
}

TEST(Balancer, WholeCostUnlearnsAFirstBandInflatedByTheStartWithinAFewFrames) {
  // With a per-row proxy (real tracers' row work): tracer 0's first band also paid a 60 ms scene
  // upload, so it first looks twenty times slower than it is. Equal finish times want the slow tracer
  // (10x slower per row) to take 720 / 11 = 65 rows; within five frames it must be near that, not
  // still holding most of the frame while the fast one's estimate creeps down a few percent a frame.
  const FixedCostFrame f{720, {0.005, 0.05}, {0.0, 0.0}};
  auto b = make_balancer("whole-cost");
  const std::vector<int> ids{0, 1};
  const std::vector<float> proxy(720, 1.0f);
  std::vector<TracerMeasurement> previous;
  std::vector<Band> bands;
  for (int frame = 0; frame < 6; ++frame) {
    bands = b->divide({f.rows, ids, previous, proxy});
    previous.clear();
    for (size_t t = 0; t < ids.size(); ++t)
      if (!bands[t].empty())
        previous.push_back({ids[t], bands[t], f.time(ids[t], bands[t]) + (frame == 0 && t == 0 ? 60.0 : 0.0)});
  }
  EXPECT_NEAR(bands[1].rows(), 65, 8);
  EXPECT_LT(idle_fraction(previous), 0.1);
}
