#include "bridge/joint/landmark_lidar_plane_cost.h"

#include "tests/testing/generic_poses.h"
#include "tests/testing/gradient_check.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <cmath>
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
  // A normal (LiDAR frame) at angle_rad from the ray to the landmark, facing the camera.
  Eigen::Vector3d NormalFromRay(double angle_rad) const {
    const Eigen::Vector3d ray =
        (cam_from_lidar.rotation.inverse() * (cam_i_from_world * landmark_in_world)).normalized();
    const Eigen::Vector3d across = ray.cross(Eigen::Vector3d(0, 0, 1)).normalized();
    return -std::cos(angle_rad) * ray + std::sin(angle_rad) * across;
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
  // The offset's derivatives too, on a surface seen at 50 deg from its normal (away from grazing,
  // where the capped offset bends too sharply for the checker's finite differences).
  setup.oblique_offset = 2e-3;
  std::unique_ptr<ceres::CostFunction> cost(LandmarkLidarPlaneCostFunctor::Create(
      Eigen::Vector3d(2.1, 0.4, -0.3), setup.NormalFromRay(50 * M_PI / 180), 0.02));
  // Ambient quaternion coordinates: checks the derivative of the whole function.
  const std::vector<const ceres::Manifold*> manifolds(6, nullptr);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(
      testing::GradientMatchesNumericDifferences(*cost, setup.Blocks(), manifolds, &results));
  // And it is not trivially zero: the landmark's Jacobian is (R_cam^T R_e n)^T / sigma, the
  // offset's -|m x X_c|^2 / sqrt(...) / sigma.
  EXPECT_GT(results.jacobians[2].norm(), 10.0);
  EXPECT_GT(results.jacobians[5].norm(), 100.0);
}

// The oblique-view offset, subtracted: none for a surface seen head on, delta d sin tan at 60 deg
// from the normal, delta d / kGrazing (0.05) at grazing view.
TEST(LandmarkLidarPlaneCost, ObliqueOffsetScalesWithDistanceAndObliqueness) {
  LandmarkSetup setup;
  setup.oblique_offset = 1e-3;
  const double distance = (setup.cam_i_from_world * setup.landmark_in_world).norm();
  const Eigen::Vector3d on_plane = setup.LandmarkInLidar();
  std::vector<double*> blocks = setup.Blocks();
  const auto residual_at = [&](double angle_deg) {
    std::unique_ptr<ceres::CostFunction> cost(LandmarkLidarPlaneCostFunctor::Create(
        on_plane, setup.NormalFromRay(angle_deg * M_PI / 180), 0.02));
    double residual = 0;
    EXPECT_TRUE(cost->Evaluate(blocks.data(), &residual, nullptr));
    return residual;
  };
  EXPECT_NEAR(residual_at(0), 0, 1e-9);
  // 60 deg: sin 60 tan 60 = 1.5, lowered by the cap's 0.05^2 / cos^2 60.
  EXPECT_NEAR(residual_at(60), -1e-3 * distance * 1.5 / 0.02 / std::sqrt(1 + 0.01), 1e-9);
  EXPECT_NEAR(residual_at(90), -1e-3 * distance / 0.05 / 0.02, 1e-9);
}

}  // namespace
}  // namespace colmap_lidar
