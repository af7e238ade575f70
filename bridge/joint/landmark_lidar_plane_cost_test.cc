#include "bridge/joint/landmark_lidar_plane_cost.h"

#include "tests/testing/generic_poses.h"
#include "tests/testing/gradient_check.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <memory>

namespace colmap_lidar {
namespace {

struct LandmarkSetup : testing::GenericStationPair {
  Eigen::Vector3d landmark_in_world = Eigen::Vector3d(0.7, -1.2, 4.1);
  Eigen::Vector3d normal_in_lidar_i = Eigen::Vector3d(0.3, 0.5, -0.8).normalized();

  Eigen::Vector3d LandmarkInLidar() const {
    return colmap::Inverse(cam_from_lidar) * cam_i_from_world * landmark_in_world;
  }
  std::vector<double*> Blocks() {
    return {cam_i_from_world.rotation.coeffs().data(),
            cam_i_from_world.translation.data(),
            landmark_in_world.data(),
            cam_from_lidar.rotation.coeffs().data(),
            cam_from_lidar.translation.data()};
  }
};

TEST(LandmarkLidarPlaneCost, ZeroOnThePlaneAndTheSignedDistanceOffIt) {
  LandmarkSetup setup;
  const Eigen::Vector3d tangent =
      setup.normal_in_lidar_i.cross(Eigen::Vector3d(1, 0, 0)).normalized();
  // q elsewhere on the landmark's plane: zero.
  const Eigen::Vector3d on_plane = setup.LandmarkInLidar() + 0.3 * tangent;
  std::vector<double*> blocks = setup.Blocks();
  double residual = 1;
  std::unique_ptr<ceres::CostFunction> exact(
      LandmarkLidarPlaneCostFunctor::Create(on_plane, setup.normal_in_lidar_i, 0.02));
  ASSERT_TRUE(exact->Evaluate(blocks.data(), &residual, nullptr));
  EXPECT_NEAR(residual, 0, 1e-12);
  // The landmark 1 cm in front of the plane (plane moved 1 cm along -n), sigma 2 cm: +0.5.
  std::unique_ptr<ceres::CostFunction> off(LandmarkLidarPlaneCostFunctor::Create(
      on_plane - 0.01 * setup.normal_in_lidar_i, setup.normal_in_lidar_i, 0.02));
  ASSERT_TRUE(off->Evaluate(blocks.data(), &residual, nullptr));
  EXPECT_NEAR(residual, 0.5, 1e-9);
}

TEST(LandmarkLidarPlaneCost, AutodiffJacobianMatchesNumericDifferences) {
  LandmarkSetup setup;
  std::unique_ptr<ceres::CostFunction> cost(LandmarkLidarPlaneCostFunctor::Create(
      Eigen::Vector3d(2.1, 0.4, -0.3), setup.normal_in_lidar_i, 0.02));
  // Ambient quaternion coordinates: checks the derivative of the whole function.
  const std::vector<const ceres::Manifold*> manifolds(5, nullptr);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(
      testing::GradientMatchesNumericDifferences(*cost, setup.Blocks(), manifolds, &results));
  // And it is not trivially zero: the landmark's Jacobian is (R_cam^T R_e n)^T / sigma.
  EXPECT_GT(results.jacobians[2].norm(), 10.0);
}

}  // namespace
}  // namespace colmap_lidar
