#include "bridge/joint/extrinsic_deviation_cost.h"

#include "tests/testing/gradient_check.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

namespace colmap_lidar {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

struct Extrinsic {
  Eigen::Quaterniond rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(1.9, Eigen::Vector3d(0.3, -0.8, 0.5).normalized()));
  Eigen::Vector3d translation = Eigen::Vector3d(0.19, -0.25, -0.05);

  std::vector<double*> Blocks() { return {rotation.coeffs().data(), translation.data()}; }
};

Eigen::Matrix<double, 6, 1> Residuals(ceres::CostFunction* cost, Extrinsic extrinsic) {
  Eigen::Matrix<double, 6, 1> residuals;
  std::vector<double*> blocks = extrinsic.Blocks();
  EXPECT_TRUE(cost->Evaluate(blocks.data(), residuals.data(), nullptr));
  return residuals;
}

// A covariance with correlations: sigmas 0.05 deg and 5 mm, rotation about z tied to y translation.
Matrix6d CorrelatedCovariance() {
  Eigen::Matrix<double, 6, 1> sigmas;
  sigmas << Eigen::Vector3d::Constant(0.05 * kDegToRad), Eigen::Vector3d::Constant(0.005);
  Matrix6d correlation = Matrix6d::Identity();
  correlation(2, 4) = correlation(4, 2) = 0.6;
  return sigmas.asDiagonal() * correlation * sigmas.asDiagonal();
}

TEST(ExtrinsicDeviationCost, ZeroAtTheReferenceAndTheMahalanobisDistanceOffIt) {
  const Extrinsic reference;
  const Matrix6d covariance = CorrelatedCovariance();
  std::unique_ptr<ceres::CostFunction> cost(ExtrinsicDeviationCostFunctor::Create(
      reference.rotation, reference.translation, WhiteningOfCovariance(covariance)));
  EXPECT_LT(Residuals(cost.get(), reference).norm(), 1e-12);
  // 0.1 deg about the camera's z axis (left of the rotation) and 4 mm along y.
  Eigen::Matrix<double, 6, 1> deviation;
  deviation << 0, 0, 0.1 * kDegToRad, 0, 0.004, 0;
  Extrinsic moved = reference;
  moved.rotation = Eigen::AngleAxisd(deviation(2), Eigen::Vector3d::UnitZ()) * reference.rotation;
  moved.translation += deviation.tail<3>();
  const double mahalanobis = deviation.dot(covariance.inverse() * deviation);
  EXPECT_NEAR(Residuals(cost.get(), moved).squaredNorm(), mahalanobis, 1e-6 * mahalanobis);
  // Without the correlation it would be 2^2 + 0.8^2 = 4.64; with it 4.25 (they agree in sign).
  EXPECT_LT(mahalanobis, 4.5);
}

TEST(ExtrinsicDeviationCost, AutodiffJacobianMatchesNumericDifferences) {
  Extrinsic reference;
  std::unique_ptr<ceres::CostFunction> cost(ExtrinsicDeviationCostFunctor::Create(
      reference.rotation, reference.translation, WhiteningOfCovariance(CorrelatedCovariance())));
  Extrinsic moved = reference;
  moved.rotation = Eigen::AngleAxisd(0.01, Eigen::Vector3d(1, 2, 3).normalized()) * moved.rotation;
  moved.translation += Eigen::Vector3d(0.003, -0.002, 0.001);
  const std::vector<const ceres::Manifold*> manifolds(2, nullptr);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(
      testing::GradientMatchesNumericDifferences(*cost, moved.Blocks(), manifolds, &results));
  EXPECT_GT(results.jacobians[0].norm(), 1000.0);  // 1 / 0.05 deg is 1146 per radian
}

TEST(ExtrinsicDeviationCost, RejectsACovarianceThatIsNotPositiveDefinite) {
  Matrix6d covariance = CorrelatedCovariance();
  covariance(5, 5) = 0;
  EXPECT_THROW(WhiteningOfCovariance(covariance), std::invalid_argument);
  covariance = CorrelatedCovariance();
  covariance(0, 1) = 1;
  EXPECT_THROW(WhiteningOfCovariance(covariance), std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
