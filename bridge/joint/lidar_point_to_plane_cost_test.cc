#include "bridge/joint/lidar_point_to_plane_cost.h"

#include "tests/testing/generic_poses.h"
#include "tests/testing/gradient_check.h"

#include "colmap/geometry/rigid3.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <memory>

namespace colmap_lidar {
namespace {

// Generic poses with lidar_i_from_lidar_j.
struct ThreeFrames : testing::GenericStationPair {
  colmap::Rigid3d LidarIFromLidarJ() const {
    return colmap::Inverse(cam_from_lidar) * cam_i_from_world * colmap::Inverse(cam_j_from_world) *
           cam_from_lidar;
  }
};

TEST(LidarPointToPlaneCost, ZeroOnThePlaneAndTheSignedDistanceOffIt) {
  ThreeFrames setup;
  const Eigen::Vector3d point_in_lidar_j(1.3, -0.4, 0.7);
  const Eigen::Vector3d normal_in_lidar_i = Eigen::Vector3d(0.3, 0.5, -0.8).normalized();
  // q on the plane through the transformed point, offset along the plane: exact data.
  const Eigen::Vector3d on_plane = setup.LidarIFromLidarJ() * point_in_lidar_j;
  const Eigen::Vector3d tangent = normal_in_lidar_i.cross(Eigen::Vector3d(1, 0, 0)).normalized();
  const Eigen::Vector3d point_in_lidar_i = on_plane + 0.2 * tangent;
  double residual = 1;
  std::unique_ptr<ceres::CostFunction> exact(LidarPointToPlaneCostFunctor::Create(
      point_in_lidar_j, point_in_lidar_i, normal_in_lidar_i, 0.02));
  std::vector<double*> blocks = setup.Blocks();
  ASSERT_TRUE(exact->Evaluate(blocks.data(), &residual, nullptr));
  EXPECT_NEAR(residual, 0, 1e-12);
  // 1 cm behind the plane (along -n) with sigma 2 cm: E_l = -0.5.
  std::unique_ptr<ceres::CostFunction> off(LidarPointToPlaneCostFunctor::Create(
      point_in_lidar_j, point_in_lidar_i + 0.01 * normal_in_lidar_i, normal_in_lidar_i, 0.02));
  ASSERT_TRUE(off->Evaluate(blocks.data(), &residual, nullptr));
  EXPECT_NEAR(residual, -0.5, 1e-9);
}

TEST(LidarPointToPlaneCost,
     AutodiffJacobianMatchesNumericDifferencesInAmbientQuaternionCoordinates) {
  ThreeFrames setup;
  std::unique_ptr<ceres::CostFunction> cost(
      LidarPointToPlaneCostFunctor::Create(Eigen::Vector3d(1.3, -0.4, 0.7),
                                           Eigen::Vector3d(-0.2, 0.9, 1.4),
                                           Eigen::Vector3d(0.3, 0.5, -0.8).normalized(),
                                           0.02));
  // Ambient quaternion coordinates: checks the autodiff derivative of the whole function.
  const std::vector<const ceres::Manifold*> manifolds(6, nullptr);
  EXPECT_TRUE(testing::GradientMatchesNumericDifferences(*cost, setup.Blocks(), manifolds));
}

}  // namespace
}  // namespace colmap_lidar
