#include "bridge/joint/variance_components.h"

#include <Eigen/Core>
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

namespace colmap_lidar {
namespace {

// A direct observation of a 3D point, whitened by sigma.
struct PointObservation {
  PointObservation(const Eigen::Vector3d& measured, double sigma)
      : measured(measured), sigma(sigma) {}
  template <typename T>
  bool operator()(const T* point, T* residuals) const {
    for (int i = 0; i < 3; ++i) residuals[i] = (point[i] - T(measured[i])) / T(sigma);
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Vector3d& measured, double sigma) {
    return new ceres::AutoDiffCostFunction<PointObservation, 3, 3>(
        new PointObservation(measured, sigma));
  }
  Eigen::Vector3d measured;
  double sigma;
};

// Points observed by two instruments of true standard deviations 2 and 0.5, both nominally 1: group
// A three times per point, group B twice.
struct TwoInstruments {
  explicit TwoInstruments(int num_points) {
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 1.0);
    for (int i = 0; i < num_points; ++i) {
      const Eigen::Vector3d truth(i, 0.5 * i, -i);
      for (int k = 0; k < 3; ++k) {
        a.push_back(truth + 2.0 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
      }
      for (int k = 0; k < 2; ++k) {
        b.push_back(truth + 0.5 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
      }
    }
    points.assign(num_points, Eigen::Vector3d::Zero());
  }

  // Solves with the given nominal sigmas and returns the components at the optimum.
  std::vector<VarianceComponent> SolveAndEstimate(double sigma_a, double sigma_b) {
    ceres::Problem problem;
    VarianceGroup group_a{"a", {}, 3 * a.size()}, group_b{"b", {}, 3 * b.size()};
    for (size_t i = 0; i < points.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        group_a.blocks.push_back(problem.AddResidualBlock(
            PointObservation::Create(a[3 * i + k], sigma_a), nullptr, points[i].data()));
      }
      for (int k = 0; k < 2; ++k) {
        group_b.blocks.push_back(problem.AddResidualBlock(
            PointObservation::Create(b[2 * i + k], sigma_b), nullptr, points[i].data()));
      }
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    return EstimateVarianceComponents(&problem, {group_a, group_b}, {});
  }

  std::vector<Eigen::Vector3d> a, b, points;
};

TEST(VarianceComponents, RedundanciesSumToObservationsMinusParameters) {
  TwoInstruments data(200);
  const std::vector<VarianceComponent> components = data.SolveAndEstimate(1.0, 1.0);
  ASSERT_EQ(components.size(), 2u);
  EXPECT_EQ(components[0].num_observations, 1800u);
  EXPECT_NEAR(components[0].parameter_share + components[1].parameter_share, 600.0, 1e-6);
  // With equal nominal weights, A (3 of 5 observations per point) determines 3/5 of each point.
  EXPECT_NEAR(components[0].parameter_share, 360.0, 1e-6);
  EXPECT_NEAR(components[0].redundancy + components[1].redundancy, 3000.0 - 600.0, 1e-6);
}

TEST(VarianceComponents, IteratedWithTheSolveTheFactorsRecoverEachInstrumentsVariance) {
  TwoInstruments data(400);
  double sigma_a = 1.0, sigma_b = 1.0;
  std::vector<VarianceComponent> components;
  for (int iteration = 0; iteration < 8; ++iteration) {
    components = data.SolveAndEstimate(sigma_a, sigma_b);
    sigma_a *= std::sqrt(components[0].factor);
    sigma_b *= std::sqrt(components[1].factor);
  }
  // 3600 and 2400 observations: the estimates' relative standard error is ~2-3 %.
  EXPECT_NEAR(sigma_a, 2.0, 0.1);
  EXPECT_NEAR(sigma_b, 0.5, 0.025);
  EXPECT_NEAR(components[0].factor, 1.0, 0.01);
  EXPECT_NEAR(components[1].factor, 1.0, 0.01);
}

TEST(VarianceComponents, AGroupWithoutRedundancyKeepsItsFactor) {
  ceres::Problem problem;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  VarianceGroup only{"only", {}, 3};
  only.blocks.push_back(problem.AddResidualBlock(
      PointObservation::Create(Eigen::Vector3d(1, 2, 3), 1.0), nullptr, point.data()));
  const std::vector<VarianceComponent> components =
      EstimateVarianceComponents(&problem, {only}, {});
  EXPECT_NEAR(components[0].redundancy, 0.0, 1e-9);
  EXPECT_EQ(components[0].factor, 1.0);
}

}  // namespace
}  // namespace colmap_lidar
