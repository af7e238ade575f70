#include "lidar/point_to_plane_icp.h"

#include "lidar/point_to_plane_association.h"
#include "tests/testing/synthetic_clouds.h"

#include <gtest/gtest.h>

#include <random>

namespace colmap_lidar {
namespace {

Eigen::Isometry3d MakePose(double angle_deg,
                           const Eigen::Vector3d& axis,
                           const Eigen::Vector3d& t) {
  return Eigen::Translation3d(t) * Eigen::AngleAxisd(angle_deg * M_PI / 180, axis.normalized());
}

double AngleDeg(const Eigen::Isometry3d& pose) {
  return Eigen::AngleAxisd(pose.linear()).angle() * 180 / M_PI;
}

TEST(PointToPlaneIcpTest, RecoversARelativePoseFromIndependentNoisySamplings) {
  const PointCloud target = testing::SyntheticRoom(1000, 10, 0.005);
  const Eigen::Isometry3d target_from_source =
      MakePose(7, Eigen::Vector3d(0.2, 0.3, 1), Eigen::Vector3d(0.4, -0.3, 0.05));
  PointCloud source = testing::SyntheticRoom(1000, 11, 0.005);  // another sampling of the same room
  for (Eigen::Vector3d& p : source.points) p = target_from_source.inverse() * p;
  const KdTree3 tree(target.points);
  // Start 3 deg and 20 cm off.
  const Eigen::Isometry3d initial =
      target_from_source *
      MakePose(3, Eigen::Vector3d(1, -1, 0.5), Eigen::Vector3d(0.12, 0.1, -0.12));
  const IcpResult result = PointToPlaneIcp(source, target, tree, initial, IcpOptions());
  EXPECT_TRUE(result.converged) << result.iterations << " iterations";
  const Eigen::Isometry3d error = result.target_from_source * target_from_source.inverse();
  EXPECT_LT(AngleDeg(error), 0.02);
  EXPECT_LT(error.translation().norm(), 0.002);
  EXPECT_GT(result.overlap_ratio, 0.95);
  EXPECT_NEAR(result.rmse, 0.005 * std::sqrt(2.0),
              0.002);  // two independent 5 mm noises
}

TEST(PointToPlaneIcpTest, DisjointCloudsHaveNoOverlap) {
  const PointCloud target = testing::SyntheticRoom(100, 12);
  PointCloud source = testing::SyntheticRoom(100, 13);
  for (Eigen::Vector3d& p : source.points) p += Eigen::Vector3d(100, 0, 0);
  const KdTree3 tree(target.points);
  const IcpResult result =
      PointToPlaneIcp(source, target, tree, Eigen::Isometry3d::Identity(), IcpOptions());
  EXPECT_EQ(result.num_inliers, 0u);
  EXPECT_FALSE(result.converged);
}

// Target points marked curved (curvature 1) whose normals are wrong and whose residuals are 2 cm off
// at the truth bias the plain ICP; with the curvatures they only count towards the overlap, and the
// ICP ends at the truth.
TEST(PointToPlaneIcpTest, CurvedTargetPointsEnterOnlyTheOverlap) {
  PointCloud target = testing::SyntheticRoom(1000, 10, 0.0);
  const PointCloud source = target;  // the same points: the truth is the identity
  std::vector<double> curvature(target.Size(), 0.0);
  for (size_t i = 0; i < target.Size(); i += 10) {
    target.points[i] += 0.02 * target.normals[i];
    target.normals[i] = (target.normals[i] + Eigen::Vector3d(0.3, -0.2, 0.4)).normalized();
    curvature[i] = 1.0;
  }
  const KdTree3 tree(target.points);
  const Eigen::Isometry3d start =
      MakePose(1, Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.05, 0, 0));
  const IcpResult plain = PointToPlaneIcp(source, target, tree, start, IcpOptions());
  const IcpResult planar = PointToPlaneIcp(source, target, tree, start, IcpOptions(), &curvature);
  EXPECT_GT(plain.target_from_source.translation().norm(), 3e-4);  // measured 0.9 mm
  EXPECT_TRUE(planar.converged);
  EXPECT_LT(planar.target_from_source.translation().norm(), 3e-5);  // the convergence tolerances
  EXPECT_LT(AngleDeg(planar.target_from_source), 1.2e-4);
  EXPECT_GT(planar.overlap_ratio, 0.99);  // the curved points still overlap
  // Every target point curved (a scene of trees and poles): the first phase's result stands.
  const std::vector<double> all_curved(target.Size(), 1.0);
  const IcpResult fallback =
      PointToPlaneIcp(source, target, tree, start, IcpOptions(), &all_curved);
  EXPECT_TRUE(fallback.converged);
  EXPECT_TRUE(fallback.target_from_source.isApprox(plain.target_from_source, 1e-12));
  EXPECT_EQ(fallback.num_inliers, plain.num_inliers);
  const std::vector<double> too_few(3, 0.0);
  EXPECT_THROW(PointToPlaneIcp(source, target, tree, start, IcpOptions(), &too_few),
               std::invalid_argument);
}

TEST(PointToPlaneAssociationTest, ResidualsMeasureTheTransformError) {
  const PointCloud target = testing::SyntheticRoom(200, 14);
  const Eigen::Isometry3d target_from_source =
      MakePose(20, Eigen::Vector3d(0.1, 0.2, 1), Eigen::Vector3d(1.0, 0.5, 0.0));
  PointCloud source = target;
  for (Eigen::Vector3d& p : source.points) p = target_from_source.inverse() * p;
  const KdTree3 tree(target.points);
  AssociationOptions options;
  options.num_samples = 3000;
  options.seed = 5;
  const auto exact = AssociatePointToPlane(source, target, tree, target_from_source, options);
  EXPECT_GT(exact.size(), 2900u);
  for (const auto& o : exact) {
    EXPECT_NEAR(o.normal_in_target.dot(target_from_source * o.point_in_source - o.point_in_target),
                0,
                1e-9);
  }
  // A 2 cm shift along x: observations on planes facing x measure it, others do not.
  const Eigen::Isometry3d shifted = Eigen::Translation3d(0.02, 0, 0) * target_from_source;
  // (Near edges the nearest point may jump to the neighbouring face: allow a few per cent.)
  const auto off = AssociatePointToPlane(source, target, tree, shifted, options);
  size_t facing_x = 0, measured = 0;
  for (const auto& o : off) {
    const double r = o.normal_in_target.dot(shifted * o.point_in_source - o.point_in_target);
    if (std::abs(o.normal_in_target.x()) > 0.99) {
      ++facing_x;
      measured += std::abs(std::abs(r) - 0.02) < 1e-9;
    }
  }
  EXPECT_GT(facing_x, 300u);
  EXPECT_GT(measured, facing_x * 95 / 100);
  // Same seed, same sample; a gate of 1 mm on the shifted pose keeps only points on planes parallel to x.
  EXPECT_EQ(AssociatePointToPlane(source, target, tree, target_from_source, options).size(),
            exact.size());
  options.max_distance = 0.001;
  for (const auto& o : AssociatePointToPlane(source, target, tree, shifted, options)) {
    EXPECT_LT(std::abs(o.normal_in_target.x()), 0.5);
  }
}

// A floor of 10 m x 10 m with a 1 m x 0.5 m wall on it: uniform draws land on the wall about 1 % of
// the time; normal-space sampling draws the two normal directions evenly.
TEST(PointToPlaneAssociationTest, NormalSpaceSamplingBalancesNormalDirections) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0, 1);
  PointCloud cloud;
  for (int k = 0; k < 20000; ++k) {
    cloud.points.emplace_back(10 * unit(rng), 10 * unit(rng), 0);
    cloud.normals.emplace_back(0, 0, 1);
  }
  for (int k = 0; k < 200; ++k) {
    cloud.points.emplace_back(5, 5 + unit(rng), 0.5 * unit(rng));
    cloud.normals.emplace_back(-1, 0, 0);
  }
  const KdTree3 tree(cloud.points);
  AssociationOptions options;
  options.num_samples = 300;
  const auto count_wall = [&](bool normal_space) {
    options.normal_space_sampling = normal_space;
    size_t wall = 0;
    const auto observations =
        AssociatePointToPlane(cloud, cloud, tree, Eigen::Isometry3d::Identity(), options);
    EXPECT_EQ(observations.size(), 300u);
    for (const auto& o : observations) wall += std::abs(o.normal_in_target.x()) > 0.9;
    return wall;
  };
  EXPECT_LT(count_wall(false), 15u);
  EXPECT_EQ(count_wall(true), 150u);
}

}  // namespace
}  // namespace colmap_lidar
