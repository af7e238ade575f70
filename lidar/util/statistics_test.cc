#include "lidar/util/statistics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace colmap_lidar {
namespace {

TEST(Statistics, MedianOfOddAndEvenCountsAndOfNone) {
  EXPECT_DOUBLE_EQ(Median({5, 1, 3}), 3);
  EXPECT_DOUBLE_EQ(Median({4, 1, 3, 2}), 2.5);
  EXPECT_TRUE(std::isnan(Median({})));
}

TEST(Statistics, QuantileIsTheValueOfTheNearestRank) {
  const std::vector<double> values = {10, 0, 5, 2, 8, 1, 9, 3, 7, 4, 6};  // 0..10
  EXPECT_DOUBLE_EQ(Quantile(values, 0), 0);
  EXPECT_DOUBLE_EQ(Quantile(values, 0.5), 5);
  EXPECT_DOUBLE_EQ(Quantile(values, 0.95), 10);  // rank 9.5 rounds to 10
  EXPECT_DOUBLE_EQ(Quantile(values, 0.94), 9);
  EXPECT_DOUBLE_EQ(Quantile(values, 2), 10);
  EXPECT_TRUE(std::isnan(Quantile({}, 0.5)));
}

}  // namespace
}  // namespace colmap_lidar
