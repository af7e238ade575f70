#include "colmap_ext/depth_prior_cost.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <array>
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
const std::array<double, 3> kNoBias = {0, 0, 0};

DepthPriorMeasurement Measurement(double depth, double sigma) {
  return {depth, sigma, Eigen::Vector2d(0.2, -0.1)};
}

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
    std::unique_ptr<ceres::CostFunction> cost(
        DepthPriorCostFunctor::Create(Measurement(depth, 0.01), type));
    EXPECT_NEAR(Evaluate(cost.get(),
                         {cam_from_world.rotation.coeffs().data(),
                          cam_from_world.translation.data(),
                          kPointInWorld.data(),
                          kNoBias.data()}),
                0,
                1e-12);
    std::unique_ptr<ceres::CostFunction> constant(
        DepthPriorConstantPoseCostFunctor::Create(cam_from_world, Measurement(depth, 0.01), type));
    EXPECT_NEAR(Evaluate(constant.get(), {kPointInWorld.data(), kNoBias.data()}), 0, 1e-12);
  }
  // 1 cm too deep with sigma 1 cm: residual -1 (the measured depth is larger than the model's).
  std::unique_ptr<ceres::CostFunction> cost(
      DepthPriorCostFunctor::Create(Measurement(point_in_cam.z() + 0.01, 0.01)));
  EXPECT_NEAR(Evaluate(cost.get(),
                       {cam_from_world.rotation.coeffs().data(),
                        cam_from_world.translation.data(),
                        kPointInWorld.data(),
                        kNoBias.data()}),
              -1.0,
              1e-9);
}

// A prior measured through a disparity bias field fits its landmark once the field is applied:
// 1/d_measured = 1/z - c0 - c1 x - c2 y.
TEST(DepthPriorCost, TheBiasFieldCorrectsTheMeasuredInverseDepth) {
  colmap::Rigid3d cam_from_world = GenericCamFromWorld();
  const double z = (cam_from_world * kPointInWorld).z();
  const std::array<double, 3> bias = {0.004, -0.002, 0.003};
  DepthPriorMeasurement measurement = Measurement(0, 0.01);
  measurement.depth = 1 / (1 / z - bias[0] - bias[1] * measurement.normalized_xy.x() -
                           bias[2] * measurement.normalized_xy.y());
  ASSERT_GT(std::abs(measurement.depth - z), 0.005);  // the field moves the depth by > 0.5 sigma
  std::unique_ptr<ceres::CostFunction> cost(DepthPriorCostFunctor::Create(measurement));
  const std::vector<const double*> blocks = {cam_from_world.rotation.coeffs().data(),
                                             cam_from_world.translation.data(),
                                             kPointInWorld.data(),
                                             bias.data()};
  EXPECT_NEAR(Evaluate(cost.get(), blocks), 0, 1e-9);
  std::unique_ptr<ceres::CostFunction> constant(
      DepthPriorConstantPoseCostFunctor::Create(cam_from_world, measurement));
  EXPECT_NEAR(Evaluate(constant.get(), {kPointInWorld.data(), bias.data()}), 0, 1e-9);
  EXPECT_GT(std::abs(Evaluate(cost.get(), {blocks[0], blocks[1], blocks[2], kNoBias.data()})), 0.5);
}

TEST(DepthPriorCost, AutodiffJacobiansMatchNumericDifferencesForZAndRangeAtAGenericPose) {
  colmap::Rigid3d cam_from_world = GenericCamFromWorld();
  Eigen::Vector3d point = kPointInWorld;
  // The checks run in the ambient 4-vector of the quaternion: on COLMAP's quaternion manifold some
  // derivatives are exactly zero by construction (z is invariant to rotation about the camera z axis, the
  // range to any rotation of the camera), which GradientChecker's relative test cannot compare.
  for (const DepthType type : {DepthType::kZ, DepthType::kRange}) {
    std::unique_ptr<ceres::CostFunction> cost(
        DepthPriorCostFunctor::Create(Measurement(2.3, 0.02), type));
    std::array<double, 3> bias = {0.004, -0.002, 0.003};
    const std::vector<const ceres::Manifold*> manifolds = {nullptr, nullptr, nullptr, nullptr};
    ceres::NumericDiffOptions numeric_options;
    ceres::GradientChecker checker(cost.get(), &manifolds, numeric_options);
    ceres::GradientChecker::ProbeResults results;
    std::vector<double*> blocks = {cam_from_world.rotation.coeffs().data(),
                                   cam_from_world.translation.data(),
                                   point.data(),
                                   bias.data()};
    EXPECT_TRUE(checker.Probe(blocks.data(), 1e-7, &results)) << results.error_log;

    std::unique_ptr<ceres::CostFunction> constant(
        DepthPriorConstantPoseCostFunctor::Create(cam_from_world, Measurement(2.3, 0.02), type));
    const std::vector<const ceres::Manifold*> no_manifold = {nullptr, nullptr};
    ceres::GradientChecker constant_checker(constant.get(), &no_manifold, numeric_options);
    std::vector<double*> constant_blocks = {point.data(), bias.data()};
    EXPECT_TRUE(constant_checker.Probe(constant_blocks.data(), 1e-7, &results))
        << results.error_log;
  }
}

}  // namespace
}  // namespace colmap_lidar
