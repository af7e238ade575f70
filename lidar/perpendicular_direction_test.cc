#include "lidar/perpendicular_direction.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

namespace colmap_lidar {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Unit normals of walls (horizontal normals in the frame where `up` is vertical) at the given
// azimuths, each perturbed by `noise_rad`, and ground normals (along `up`) that must stay out.
std::vector<Eigen::Vector3d> WallAndGroundNormals(const Eigen::Vector3d& up,
                                                  const std::vector<double>& azimuths_deg,
                                                  size_t per_wall,
                                                  double noise_rad,
                                                  std::mt19937* rng) {
  std::normal_distribution<double> noise(0.0, noise_rad);
  const Eigen::Quaterniond frame = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), up);
  std::vector<Eigen::Vector3d> normals;
  auto perturbed = [&](const Eigen::Vector3d& n) {
    return (n + Eigen::Vector3d(noise(*rng), noise(*rng), noise(*rng))).normalized();
  };
  for (const double azimuth : azimuths_deg) {
    const Eigen::Vector3d n(std::cos(azimuth * kDeg), std::sin(azimuth * kDeg), 0);
    for (size_t i = 0; i < per_wall; ++i) normals.push_back(perturbed(frame * n));
  }
  for (size_t i = 0; i < per_wall; ++i) normals.push_back(perturbed(up));
  return normals;
}

// Tilt of `estimate` from `truth` in the estimate's tangent basis [rad].
Eigen::Vector2d TiltError(const PerpendicularDirection& estimate, const Eigen::Vector3d& truth) {
  return estimate.tangent.transpose() * (truth - estimate.direction);
}

TEST(PerpendicularDirectionTest, FindsTheVerticalOfTwoWallDirectionsWithCoveringSigma) {
  // 0.7 deg between the guess and the true vertical; 1 deg normal noise.
  const Eigen::Vector3d up = Eigen::AngleAxisd(0.7 * kDeg, Eigen::Vector3d(1, 2, 0).normalized()) *
                             Eigen::Vector3d::UnitZ();
  const PerpendicularDirectionOptions options;
  int within_2_sigma = 0;
  double largest_error_deg = 0;
  constexpr int kDraws = 40;
  for (int seed = 0; seed < kDraws; ++seed) {
    std::mt19937 rng(seed);
    const auto normals = WallAndGroundNormals(up, {0, 180, 90}, 100, 1.0 * kDeg, &rng);
    const PerpendicularDirection fit =
        FitPerpendicularDirection(normals, {}, Eigen::Vector3d::UnitZ(), options);
    ASSERT_TRUE(fit.valid);
    const Eigen::Vector2d error = TiltError(fit, up);
    largest_error_deg = std::max(largest_error_deg, error.norm() / kDeg);
    // Mahalanobis distance in 2-D: 86.5 % of draws within 2.
    if (error.dot(fit.covariance.inverse() * error) < 4.0) ++within_2_sigma;
  }
  std::cout << "largest error " << largest_error_deg << " deg, " << within_2_sigma << " of "
            << kDraws << " within 2 sigma\n";
  // Measured: largest 0.24 deg (1 deg noise on 300 normals).
  EXPECT_LT(largest_error_deg, 0.4);
  EXPECT_GE(within_2_sigma, 29);  // 34.6 expected of 40; measured 32
}

TEST(PerpendicularDirectionTest, OneWallDirectionLeavesTheOtherTiltUnknown) {
  const Eigen::Vector3d up =
      Eigen::AngleAxisd(0.5 * kDeg, Eigen::Vector3d::UnitX()) * Eigen::Vector3d::UnitZ();
  std::mt19937 rng(3);
  // Walls facing +-x only (a street along y): the lean across it (about y) is measured, the lean
  // along it (about x, which moves the vertical within the walls' plane) is not.
  const auto normals = WallAndGroundNormals(up, {0, 180}, 200, 0.5 * kDeg, &rng);
  const PerpendicularDirection fit = FitPerpendicularDirection(
      normals, {}, Eigen::Vector3d::UnitZ(), PerpendicularDirectionOptions());
  ASSERT_TRUE(fit.valid);
  // Variance along the wall direction's lean: unknown; across it: small.
  const Eigen::Vector2d along = fit.tangent.transpose() * Eigen::Vector3d::UnitY();
  const Eigen::Vector2d across = fit.tangent.transpose() * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(along.dot(fit.covariance * along), kUnknownTiltVariance, 1e-6);
  EXPECT_LT(std::sqrt(across.dot(fit.covariance * across)) / kDeg, 0.05);
  // The unmeasured lean stays at the guess: the direction has no y component.
  EXPECT_LT(std::abs(fit.direction.y()), 1e-6);
  EXPECT_LT(std::abs(fit.direction.x()), 0.05 * kDeg);
}

TEST(PerpendicularDirectionTest, TooFewInliersGiveNoDirection) {
  std::mt19937 rng(1);
  const auto normals = WallAndGroundNormals(Eigen::Vector3d::UnitZ(), {0}, 5, 0.0, &rng);
  EXPECT_FALSE(FitPerpendicularDirection(
                   normals, {}, Eigen::Vector3d::UnitZ(), PerpendicularDirectionOptions())
                   .valid);
  EXPECT_THROW(FitPerpendicularDirection(
                   normals, {1.0}, Eigen::Vector3d::UnitZ(), PerpendicularDirectionOptions()),
               std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
