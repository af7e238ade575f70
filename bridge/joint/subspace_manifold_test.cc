#include "bridge/joint/subspace_manifold.h"

#include <Eigen/Geometry>
#include <ceres/autodiff_cost_function.h>
#include <ceres/manifold_test_utils.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <gtest/gtest.h>

#include <memory>

namespace colmap_lidar {
namespace {

using ceres::HasCorrectMinusJacobianAt;
using ceres::HasCorrectPlusJacobianAt;
using ceres::HasCorrectRightMultiplyByPlusJacobianAt;
using ceres::MinusPlusIsIdentityAt;
using ceres::MinusPlusJacobianIsIdentityAt;
using ceres::PlusMinusIsIdentityAt;
using ceres::Vector;
using ceres::XMinusXIsZeroAt;
using ceres::XPlusZeroIsXAt;

Eigen::Matrix3d Projection(const Eigen::Vector3d& direction) {
  const Eigen::Vector3d d = direction.normalized();
  return d * d.transpose();
}

TEST(SubspaceManifold, FreeAndHeldDirectionsSplitTheSpace) {
  const Eigen::Matrix3d held = Projection({0.3, -0.8, 0.5});
  const Eigen::MatrixXd free = FreeDirectionsBasis(held);
  const Eigen::MatrixXd held_directions = HeldDirectionsOf(held);
  ASSERT_EQ(free.cols(), 2);
  ASSERT_EQ(held_directions.cols(), 1);
  EXPECT_LT((free.transpose() * free - Eigen::Matrix2d::Identity()).norm(), 1e-12);
  EXPECT_LT((free.transpose() * held_directions).norm(), 1e-12);
  EXPECT_LT((held_directions * held_directions.transpose() - held).norm(), 1e-12);
  EXPECT_EQ(FreeDirectionsBasis(Eigen::Matrix3d::Zero()).cols(), 3);
  EXPECT_EQ(HeldDirectionsOf(Eigen::Matrix3d::Zero()).cols(), 0);
}

TEST(SubspaceManifold, QuaternionSubspaceKeepsCeresInvariants) {
  const SubspaceManifold manifold(std::make_unique<ceres::EigenQuaternionManifold>(),
                                  FreeDirectionsBasis(Projection({0.3, -0.8, 0.5})));
  Eigen::Quaterniond q(Eigen::AngleAxisd(1.9, Eigen::Vector3d(0.2, 0.6, -0.7).normalized()));
  Vector x = Eigen::Map<const Eigen::Vector4d>(q.coeffs().data());
  Vector delta(2), y(4);
  delta << 0.07, -0.11;
  Vector other(2);
  other << -0.03, 0.05;
  ASSERT_TRUE(manifold.Plus(x.data(), other.data(), y.data()));
  EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-9);
}

TEST(SubspaceManifold, EuclideanSubspaceKeepsCeresInvariants) {
  const SubspaceManifold manifold(std::make_unique<ceres::EuclideanManifold<3>>(),
                                  FreeDirectionsBasis(Projection({0, 1, 0})));
  Vector x(3), delta(2), y(3);
  x << 0.19, -0.25, -0.05;
  delta << 0.3, -0.2;
  y << 0.5, -0.25, 0.4;  // reachable: same y as x
  EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-12);
}

// Pulls a translation towards a target: the held direction stays where it started exactly.
struct PullCost {
  template <typename T>
  bool operator()(const T* const t, T* residuals) const {
    residuals[0] = t[0] - T(1.0);
    residuals[1] = t[1] - T(2.0);
    residuals[2] = t[2] - T(3.0);
    return true;
  }
};

TEST(SubspaceManifold, SolveLeavesHeldDirectionAtItsStart) {
  const Eigen::Vector3d held_direction = Eigen::Vector3d(1, 1, 0).normalized();
  Eigen::Vector3d t(0.2, -0.1, 0.0);
  const double start_along_held = held_direction.dot(t);
  ceres::Problem problem;
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<PullCost, 3, 3>(new PullCost), nullptr, t.data());
  problem.SetManifold(t.data(),
                      new SubspaceManifold(std::make_unique<ceres::EuclideanManifold<3>>(),
                                           FreeDirectionsBasis(Projection(held_direction))));
  ceres::Solver::Options options;
  options.function_tolerance = options.gradient_tolerance = options.parameter_tolerance = 1e-15;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  EXPECT_NEAR(held_direction.dot(t), start_along_held, 1e-12);
  EXPECT_NEAR(
      t.z(), 3.0, 1e-6);  // the free directions reach the target (to the solver's tolerance)
  EXPECT_NEAR((Eigen::Vector3d(1, -1, 0).normalized()).dot(t - Eigen::Vector3d(1, 2, 3)), 0, 1e-6);
}

}  // namespace
}  // namespace colmap_lidar
