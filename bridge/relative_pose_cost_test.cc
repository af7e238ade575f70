#include "bridge/relative_pose_cost.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <memory>

namespace colmap_lidar {
namespace {

colmap::Rigid3d Pose(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  return colmap::Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized())), t);
}

TEST(RelativePoseCost, ZeroAtTheTruthTwoSigmaForOneCentimetreAndAutodiffMatchesNumeric) {
  colmap::Rigid3d cam_i_from_world = Pose(0.7, {0.2, -0.9, 0.4}, {0.3, -0.2, 1.9});
  colmap::Rigid3d cam_j_from_world = Pose(-1.2, {0.7, 0.3, -0.5}, {-0.8, 0.4, 2.4});
  const colmap::Rigid3d measured = cam_i_from_world * colmap::Inverse(cam_j_from_world);
  std::unique_ptr<ceres::CostFunction> cost(
      RelativePoseCostFunctor::Create(measured, 0.001, 0.005));
  std::vector<double*> blocks = {cam_i_from_world.rotation.coeffs().data(),
                                 cam_i_from_world.translation.data(),
                                 cam_j_from_world.rotation.coeffs().data(),
                                 cam_j_from_world.translation.data()};
  double residuals[6];
  ASSERT_TRUE(cost->Evaluate(blocks.data(), residuals, nullptr));
  for (const double r : residuals) EXPECT_NEAR(r, 0, 1e-9);

  // 1 cm off in translation: 2 sigma on that axis.
  std::unique_ptr<ceres::CostFunction> shifted(RelativePoseCostFunctor::Create(
      colmap::Rigid3d(measured.rotation, measured.translation + Eigen::Vector3d(0, 0.01, 0)),
      0.001,
      0.005));
  ASSERT_TRUE(shifted->Evaluate(blocks.data(), residuals, nullptr));
  EXPECT_NEAR(residuals[4], -2.0, 1e-6);

  // Gradients where every residual is far from zero (rotation and translation both off).
  std::unique_ptr<ceres::CostFunction> off(RelativePoseCostFunctor::Create(
      Pose(0.05, {0.3, 0.4, -0.2}, {0.02, -0.01, 0.03}) * measured, 0.001, 0.005));
  const std::vector<const ceres::Manifold*> manifolds(4, nullptr);
  ceres::NumericDiffOptions numeric_options;
  ceres::GradientChecker checker(off.get(), &manifolds, numeric_options);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(blocks.data(), 1e-6, &results)) << results.error_log;
}

}  // namespace
}  // namespace colmap_lidar
