#include "lidar/revisit_closure.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace colmap_lidar {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

Eigen::Isometry3d Pose(double x, double y, double yaw) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, 0);
  return pose;
}

// Out along y = -1.8 at 1 m per frame to x = 40, back along y = +1.8.
std::vector<Eigen::Isometry3d> OutAndBack() {
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k <= 40; ++k) poses.push_back(Pose(k, -1.8, 0));
  for (int k = 0; k <= 40; ++k) poses.push_back(Pose(40 - k, 1.8, M_PI));
  return poses;
}

// The increment [omega, t] of `perturbed` against `nominal` on the left: perturbed nominal^-1.
Vector6d LeftIncrement(const Eigen::Isometry3d& perturbed, const Eigen::Isometry3d& nominal) {
  const Eigen::Isometry3d e = perturbed * nominal.inverse();
  const Eigen::AngleAxisd rotation(e.linear());
  Vector6d increment;
  increment << rotation.angle() * rotation.axis(), e.translation();
  return increment;
}

Eigen::Isometry3d SmallExp(const Vector6d& d) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const double angle = d.head<3>().norm();
  if (angle > 0) pose.linear() = Eigen::AngleAxisd(angle, d.head<3>() / angle).toRotationMatrix();
  pose.translation() = d.tail<3>();
  return pose;
}

TEST(RevisitCandidates, PairsTheWayBackWithTheWayOutFarAlongThePath) {
  const std::vector<Eigen::Isometry3d> poses = OutAndBack();
  RevisitOptions options;
  options.keyframe_spacing_m = 4.5;  // every fifth frame, clear of rounding
  size_t num_keyframes = 0;
  const auto pairs = RevisitCandidates(poses, options, &num_keyframes);
  EXPECT_EQ(num_keyframes, 17u);  // x = 0, 5, .., 40 out; x = 39, 34, .., 4 back
  ASSERT_FALSE(pairs.empty());
  for (const auto& [earlier, later] : pairs) {
    EXPECT_LE(earlier, 40u);
    EXPECT_GT(later, 40u);
    EXPECT_LE((poses[later].translation() - poses[earlier].translation()).norm(), 10.0);
  }
  // The last keyframe back (x = 4) is nearest to the frame at x = 4 of the way out; the first pair
  // (x = 19 back, x = 14 out) is the first within 10 m that is 50 m back along the path.
  EXPECT_EQ(pairs.back(), std::make_pair(size_t{4}, size_t{77}));
  EXPECT_EQ(pairs.front(), std::make_pair(size_t{14}, size_t{62}));
}

// The drift model's covariance against the spread of the relative pose over sampled drifts, on a
// path that turns: the adjoint carries an early rotation error to every later position.
TEST(DriftCovariance, MatchesSampledSystematicDrifts) {
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k <= 60; ++k) {
    const double yaw = k < 20 ? 0 : std::min(1.0, (k - 20) / 20.0) * M_PI / 2;
    poses.push_back(k == 0 ? Pose(0, 0, 0) : poses.back() * Pose(1.0, 0, 0));
    poses.back().linear() = Pose(0, 0, yaw).linear();
  }
  RevisitOptions options;
  options.drift.translation = 0.001;
  options.drift.rotation_deg_per_m = 0.005;
  const Matrix6d model = DriftCovariance(poses, 0, 60, options);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  Vector6d sigma_per_metre;
  sigma_per_metre << Eigen::Vector3d::Constant(options.drift.rotation_deg_per_m * M_PI / 180),
      Eigen::Vector3d::Constant(options.drift.translation);
  Matrix6d sampled = Matrix6d::Zero();
  const int kDraws = 4000;
  for (int draw = 0; draw < kDraws; ++draw) {
    Vector6d u;
    for (int a = 0; a < 6; ++a) u(a) = sigma_per_metre(a) * normal(rng);
    Eigen::Isometry3d end = Eigen::Isometry3d::Identity();
    for (int k = 1; k <= 60; ++k) {
      const Eigen::Isometry3d step = poses[k - 1].inverse() * poses[k];
      end = end * SmallExp(step.translation().norm() * u) * step;
    }
    const Vector6d increment = LeftIncrement(end, poses[0].inverse() * poses[60]);
    sampled += increment * increment.transpose() / kDraws;
  }
  for (int a = 0; a < 6; ++a) {
    EXPECT_NEAR(sampled(a, a) / model(a, a), 1.0, 0.1) << "axis " << a;
  }
  // The heading's error moves the end across the first leg: yaw and y are correlated.
  EXPECT_GT(std::abs(model(2, 4)), 0.5 * std::sqrt(model(2, 2) * model(4, 4)));
}

// A revisit that agrees with the odometry passes; one slid 8 m along a straight street of 60 m, or
// turned by 3 deg, is refused; one 0.4 m off (the odometry's drift over 60 m is 0.6 m) passes.
TEST(RevisitChi2, RefusesARevisitThatContradictsTheOdometry) {
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k <= 60; ++k) poses.push_back(Pose(k, 0, 0));
  const RevisitOptions options;
  LidarEdge edge;
  edge.target = 0;
  edge.source = 60;
  edge.registration.hessian = 1e4 * Matrix6d::Identity();
  edge.registration.rmse = 0.03;
  edge.target_from_source = poses[0].inverse() * poses[60];
  EXPECT_LT(RevisitChi2(poses, edge, options), 1e-9);
  edge.target_from_source.translation().x() += 0.4;
  EXPECT_LT(RevisitChi2(poses, edge, options), options.max_chi2);
  edge.target_from_source.translation().x() += 7.6;
  EXPECT_GT(RevisitChi2(poses, edge, options), options.max_chi2);
  edge.target_from_source = Pose(60, 0, 3 * M_PI / 180);
  EXPECT_GT(RevisitChi2(poses, edge, options), options.max_chi2);
}

}  // namespace
}  // namespace colmap_lidar
