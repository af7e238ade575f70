#include "lidar/util/parallel_for_each.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace colmap_lidar {
namespace {

TEST(ParallelForEach, RunsEveryItemOnceAndRethrowsTheLowestFailure) {
  std::vector<int> runs(100, 0);
  EXPECT_THROW(
      {
        try {
          ParallelForEach(100, [&](int i) {
            ++runs[i];
            if (i == 37 || i == 80) throw std::runtime_error("item " + std::to_string(i));
          });
        } catch (const std::runtime_error& error) {
          EXPECT_STREQ(error.what(), "item 37");
          throw;
        }
      },
      std::runtime_error);
  for (int count : runs) EXPECT_EQ(count, 1);
}

}  // namespace
}  // namespace colmap_lidar
