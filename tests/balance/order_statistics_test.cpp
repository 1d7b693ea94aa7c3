#include "cohort/balance/order_statistics.h"

#include <gtest/gtest.h>

namespace cohort {
namespace {

TEST(OrderStatistics, MedianOfOddAndEvenCountsInAnyOrder) {
  EXPECT_DOUBLE_EQ(median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_DOUBLE_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);  // the mean of the middle two
  EXPECT_DOUBLE_EQ(median({7.0}), 7.0);
  EXPECT_DOUBLE_EQ(median({}), 0.0);
}

TEST(OrderStatistics, QuantilesInterpolateBetweenRanksAndClampAtTheEnds) {
  const std::vector<double> v{10.0, 0.0, 30.0, 20.0, 40.0};
  EXPECT_DOUBLE_EQ(quantile(v, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(quantile(v, 1.0), 40.0);
  EXPECT_DOUBLE_EQ(quantile(v, 0.95), 38.0);  // rank 3.8: 30 + 0.8 x 10
  EXPECT_DOUBLE_EQ(quantile(v, 1.5), 40.0);
  EXPECT_DOUBLE_EQ(quantile(v, -1.0), 0.0);
}

}  // namespace
}  // namespace cohort
