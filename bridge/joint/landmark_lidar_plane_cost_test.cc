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
  double oblique_offset = 0;

  Eigen::Vector3d LandmarkInLidar() const {
    return colmap::Inverse(cam_from_lidar) * cam_i_from_world * landmark_in_world;
  }
  std::vector<double*> Blocks() {
    return {cam_i_from_world.rotation.coeffs().data(),
            cam_i_from_world.translation.data(),
            landmark_in_world.data(),
            cam_from_lidar.rotation.coeffs().data(),
            cam_from_lidar.translation.data(),
            &oblique_offset};
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
  setup.oblique_offset = 2e-3;  // the offset's derivatives too
  const std::vector<const ceres::Manifold*> manifolds(6, nullptr);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(
      testing::GradientMatchesNumericDifferences(*cost, setup.Blocks(), manifolds, &results));
  // And it is not trivially zero: the landmark's Jacobian is (R_cam^T R_e n)^T / sigma.
  EXPECT_GT(results.jacobians[2].norm(), 10.0);
}

// The oblique-view offset: delta times |n x X| in camera i's frame, subtracted; none for a surface
// seen head on, delta times the distance at grazing view.
TEST(LandmarkLidarPlaneCost, ObliqueOffsetScalesWithDistanceAndObliqueness) {
  LandmarkSetup setup;
  setup.oblique_offset = 1e-3;
  const Eigen::Vector3d landmark_in_cam = setup.cam_i_from_world * setup.landmark_in_world;
  const Eigen::Vector3d on_plane = setup.LandmarkInLidar();
  std::vector<double*> blocks = setup.Blocks();
  double residual = 0;
  // Head on: the normal along the ray (in the LiDAR frame).
  const Eigen::Vector3d ray_in_lidar =
      (setup.cam_from_lidar.rotation.inverse() * landmark_in_cam).normalized();
  std::unique_ptr<ceres::CostFunction> head_on(
      LandmarkLidarPlaneCostFunctor::Create(on_plane, -ray_in_lidar, 0.02));
  ASSERT_TRUE(head_on->Evaluate(blocks.data(), &residual, nullptr));
  EXPECT_NEAR(residual, 0, 1e-9);
  // Grazing: the normal perpendicular to the ray; the offset is delta times the distance.
  const Eigen::Vector3d grazing = ray_in_lidar.cross(Eigen::Vector3d(0, 0, 1)).normalized();
  std::unique_ptr<ceres::CostFunction> grazing_cost(
      LandmarkLidarPlaneCostFunctor::Create(on_plane, grazing, 0.02));
  ASSERT_TRUE(grazing_cost->Evaluate(blocks.data(), &residual, nullptr));
  EXPECT_NEAR(residual, -1e-3 * landmark_in_cam.norm() / 0.02, 1e-9);
}

}  // namespace
}  // namespace colmap_lidar
