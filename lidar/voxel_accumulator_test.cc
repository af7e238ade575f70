#include "lidar/voxel_accumulator.h"

#include <gtest/gtest.h>

#include <map>
#include <random>

namespace colmap_lidar {
namespace {

TEST(VoxelAccumulator, MergesPointsOfOneVoxelAndKeepsOthersApart) {
  VoxelAccumulator accumulator(0.01);
  // Two stations' points in the same 1 cm voxel, one point in the next voxel.
  accumulator.Add(
      Eigen::Vector3d(0.002, 0.002, 0.002), Eigen::Vector3f(0, 0, 1), Color3ub(100, 0, 0));
  accumulator.Add(
      Eigen::Vector3d(0.004, 0.006, 0.008), Eigen::Vector3f(0, 1, 0), Color3ub(200, 50, 0));
  accumulator.Add(
      Eigen::Vector3d(0.015, 0.002, 0.002), Eigen::Vector3f::Zero(), Color3ub(0, 0, 255));
  accumulator.Add(
      Eigen::Vector3d(std::nan(""), 0, 0), Eigen::Vector3f::Zero(), Color3ub(0, 0, 0));  // ignored
  EXPECT_EQ(accumulator.NumPointsAdded(), 3u);
  EXPECT_EQ(accumulator.NumVoxels(), 2u);
  const PointCloud merged = accumulator.Extract();
  ASSERT_EQ(merged.Size(), 2u);
  for (size_t i = 0; i < merged.Size(); ++i) {
    if (merged.points[i].x() < 0.01) {
      EXPECT_TRUE(merged.points[i].isApprox(Eigen::Vector3d(0.003, 0.004, 0.005)));
      EXPECT_NEAR(merged.normals[i].norm(), 1, 1e-6);  // float normals
      EXPECT_NEAR(merged.normals[i].y(), std::sqrt(0.5), 1e-6);
      EXPECT_EQ(merged.colors[i], Color3ub(150, 25, 0));
    } else {
      EXPECT_TRUE(merged.normals[i].isZero());  // no normal given: none invented
      EXPECT_EQ(merged.colors[i], Color3ub(0, 0, 255));
    }
  }
  EXPECT_EQ(accumulator.Extract(2).Size(), 1u);  // voxels seen at least twice
}

TEST(VoxelAccumulator, NegativeCoordinatesDoNotShareVoxelsWithPositiveOnes) {
  VoxelAccumulator accumulator(0.01);
  accumulator.Add(Eigen::Vector3d(-0.001, 0, 0), Eigen::Vector3f::Zero(), {});
  accumulator.Add(Eigen::Vector3d(0.001, 0, 0), Eigen::Vector3f::Zero(), {});
  EXPECT_EQ(accumulator.NumVoxels(), 2u);
  EXPECT_THROW(VoxelAccumulator(0), std::invalid_argument);
}

TEST(VoxelAccumulator, MergesThroughManyBufferFlushesLikeAMap) {
  // A buffer of 100 points: the 20,000 points below are merged in about 200 steps, into voxels
  // first seen early and late; the result must equal a plain map from voxel to sums.
  VoxelAccumulator accumulator(0.1, 100);
  std::map<uint64_t, std::pair<Eigen::Vector3d, int>> expected;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-2, 2);
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d point(coordinate(rng), coordinate(rng), 0.05 + 0.1 * (i % 3));
    accumulator.Add(point, Eigen::Vector3f(0, 0, 1), Color3ub(i % 256, 0, 0));
    auto& [sum, count] =
        expected.try_emplace(VoxelKey(point, 0.1), Eigen::Vector3d::Zero(), 0).first->second;
    sum += point;
    ++count;
  }
  ASSERT_EQ(accumulator.NumVoxels(), expected.size());
  const PointCloud merged = accumulator.Extract();
  ASSERT_EQ(merged.Size(), expected.size());
  size_t k = 0;
  for (const auto& [key, sum_and_count] : expected) {  // Extract's order is the keys'
    EXPECT_EQ(VoxelKey(merged.points[k], 0.1), key);
    EXPECT_LT((merged.points[k] - sum_and_count.first / sum_and_count.second).norm(), 1e-12);
    ++k;
  }
}

// 1.2 M voxels span two chunks of 2^20: extracting while freeing the chunks gives the same cloud as
// extracting, and leaves the accumulator empty.
TEST(VoxelAccumulator, ExtractAndClearGivesExtractsCloudAcrossChunks) {
  VoxelAccumulator accumulator(0.01, 300000);
  for (int i = 0; i < 1200000; ++i) {
    const Eigen::Vector3d point(0.01 * (i % 1000) + 0.005, 0.01 * (i / 1000) + 0.005, 0.005);
    accumulator.Add(point, Eigen::Vector3f(0, 0, 1), Color3ub(i % 256, 0, 0));
  }
  const PointCloud extracted = accumulator.Extract();
  const PointCloud taken = accumulator.ExtractAndClear();
  ASSERT_EQ(extracted.Size(), 1200000u);
  ASSERT_EQ(taken.Size(), extracted.Size());
  EXPECT_TRUE(taken.points == extracted.points);
  EXPECT_TRUE(taken.colors == extracted.colors);
  EXPECT_EQ(accumulator.NumVoxels(), 0u);
  EXPECT_EQ(accumulator.Extract().Size(), 0u);
}

TEST(VoxelAccumulator, NeighbourKeysStepOneVoxelAlongEachAxis) {
  const Eigen::Vector3d point(-0.35, 0.12, 7.01);
  for (const Eigen::Vector3i& offset : {Eigen::Vector3i(1, 0, 0),
                                        Eigen::Vector3i(0, -1, 0),
                                        Eigen::Vector3i(-1, 1, 1),
                                        Eigen::Vector3i(0, 0, -1)}) {
    EXPECT_EQ(NeighbourVoxelKey(VoxelKey(point, 0.1), offset),
              VoxelKey(point + 0.1 * offset.cast<double>(), 0.1));
  }
}

}  // namespace
}  // namespace colmap_lidar
