#include "lidar/voxel_accumulator.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace colmap_lidar
