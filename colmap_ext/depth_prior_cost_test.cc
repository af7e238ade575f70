#include "colmap_ext/depth_prior_cost.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <memory>

namespace colmap_lidar {
namespace {

// A generic pose: no axis-aligned rotation, translation on all axes.
colmap::Rigid3d GenericCamFromWorld() {
  return colmap::Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.8, 0.5).normalized())),
      Eigen::Vector3d(0.4, -1.2, 2.1));
}

const Eigen::Vector3d kPointInWorld(0.9, -0.3, 1.7);

double Evaluate(ceres::CostFunction* cost, std::vector<const double*> blocks) {
  double residual = 0;
  EXPECT_TRUE(cost->Evaluate(blocks.data(), &residual, nullptr));
  return residual;
}

TEST(DepthPriorCost, ZeroResidualOnExactDataForZAndRange) {
  colmap::Rigid3d cam_from_world = GenericCamFromWorld();
  const Eigen::Vector3d point_in_cam = cam_from_world * kPointInWorld;
  ASSERT_GT(point_in_cam.z(), 0);
  for (const DepthType type : {DepthType::kZ, DepthType::kRange}) {
    const double depth = type == DepthType::kZ ? point_in_cam.z() : point_in_cam.norm();
    std::unique_ptr<ceres::CostFunction> cost(DepthPriorCostFunctor::Create(depth, 0.01, type));
    EXPECT_NEAR(Evaluate(cost.get(),
                         {cam_from_world.rotation.coeffs().data(),
                          cam_from_world.translation.data(),
                          kPointInWorld.data()}),
                0,
                1e-12);
    std::unique_ptr<ceres::CostFunction> constant(
        DepthPriorConstantPoseCostFunctor::Create(cam_from_world, depth, 0.01, type));
    EXPECT_NEAR(Evaluate(constant.get(), {kPointInWorld.data()}), 0, 1e-12);
  }
  // 1 cm too deep with sigma 1 cm: residual -1 (the measured depth is larger than the model's).
  std::unique_ptr<ceres::CostFunction> cost(
      DepthPriorCostFunctor::Create(point_in_cam.z() + 0.01, 0.01));
  EXPECT_NEAR(Evaluate(cost.get(),
                       {cam_from_world.rotation.coeffs().data(),
                        cam_from_world.translation.data(),
                        kPointInWorld.data()}),
              -1.0,
              1e-9);
}

TEST(DepthPriorCost, AutodiffJacobiansMatchNumericDifferencesForZAndRangeAtAGenericPose) {
  colmap::Rigid3d cam_from_world = GenericCamFromWorld();
  Eigen::Vector3d point = kPointInWorld;
  // The checks run in the ambient 4-vector of the quaternion: on COLMAP's quaternion manifold some
  // derivatives are exactly zero by construction (z is invariant to rotation about the camera z axis, the
  // range to any rotation of the camera), which GradientChecker's relative test cannot compare.
  for (const DepthType type : {DepthType::kZ, DepthType::kRange}) {
    std::unique_ptr<ceres::CostFunction> cost(DepthPriorCostFunctor::Create(2.3, 0.02, type));
    const std::vector<const ceres::Manifold*> manifolds = {nullptr, nullptr, nullptr};
    ceres::NumericDiffOptions numeric_options;
    ceres::GradientChecker checker(cost.get(), &manifolds, numeric_options);
    ceres::GradientChecker::ProbeResults results;
    std::vector<double*> blocks = {
        cam_from_world.rotation.coeffs().data(), cam_from_world.translation.data(), point.data()};
    EXPECT_TRUE(checker.Probe(blocks.data(), 1e-7, &results)) << results.error_log;

    std::unique_ptr<ceres::CostFunction> constant(
        DepthPriorConstantPoseCostFunctor::Create(cam_from_world, 2.3, 0.02, type));
    const std::vector<const ceres::Manifold*> no_manifold = {nullptr};
    ceres::GradientChecker constant_checker(constant.get(), &no_manifold, numeric_options);
    double* point_block = point.data();
    EXPECT_TRUE(constant_checker.Probe(&point_block, 1e-7, &results)) << results.error_log;
  }
}

}  // namespace
}  // namespace colmap_lidar
