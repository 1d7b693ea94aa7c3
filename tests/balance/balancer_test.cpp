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
    EXPECT_EQ(check_bands(rows, bands), "") << b.name() << " frame " << i;
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
  ASSERT_EQ(check_bands(100, bands), "");
  // Tracer 1 reports no time (it was dropped); tracer 7 joins.
  std::vector<TracerMeasurement> prev{{0, bands[0], 4.0}, {1, bands[1], 0.0}};
  bands = b->divide({100, {0, 1, 7}, prev, {}});
  ASSERT_EQ(bands.size(), 3u);
  ASSERT_EQ(check_bands(100, bands), "");
  // Tracer 0 leaves; a measurement for it is still in the list and must be ignored for banding.
  prev = {{0, bands[0], 1.0}, {1, bands[1], 3.0}, {7, bands[2], 3.0}};
  bands = b->divide({100, {1, 7}, prev, {}});
  ASSERT_EQ(bands.size(), 2u);
  EXPECT_EQ(check_bands(100, bands), "");
  // All zero times, then a resolution change.
  prev = {{1, bands[0], 0.0}, {7, bands[1], 0.0}};
  bands = b->divide({100, {1, 7}, prev, {}});
  EXPECT_EQ(check_bands(100, bands), "");
  bands = b->divide({37, {1, 7}, prev, {}});
  EXPECT_EQ(check_bands(37, bands), "");
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
