#include "bridge/joint/undetermined_parameters.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

namespace colmap_lidar {
namespace {

Eigen::SparseMatrix<double> Normal(const Eigen::MatrixXd& jacobian) {
  return Eigen::MatrixXd(jacobian.transpose() * jacobian).sparseView();
}

Eigen::MatrixXd RandomJacobian(int rows, int cols, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd jacobian(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) jacobian(r, c) = normal(random);
  }
  return jacobian;
}

TEST(DependentColumns, AFullRankMatrixHasNoneEvenWhenBadlyScaled) {
  Eigen::MatrixXd jacobian = RandomJacobian(20, 6, 1);
  jacobian.col(2) *= 1e6;
  jacobian.col(4) *= 1e-6;
  EXPECT_TRUE(DependentColumns(Normal(jacobian)).empty());
}

TEST(DependentColumns, OneColumnOfAnExactlyDependentSetAndEveryEmptyColumnAreNamed) {
  Eigen::MatrixXd jacobian = RandomJacobian(20, 6, 2);
  jacobian.col(5) = jacobian.col(1) - 2 * jacobian.col(3);
  jacobian.col(0).setZero();
  const std::vector<int> dependent = DependentColumns(Normal(jacobian));
  ASSERT_EQ(dependent.size(), 2u);
  EXPECT_EQ(dependent[0], 0);
  EXPECT_TRUE(dependent[1] == 1 || dependent[1] == 3 || dependent[1] == 5) << dependent[1];
}

TEST(DependentColumns, ANearlyDependentColumnBelowTheThresholdOnlyIsNamed) {
  Eigen::MatrixXd jacobian = RandomJacobian(20, 4, 3);
  const Eigen::VectorXd noise = RandomJacobian(20, 1, 4);
  jacobian.col(3) = jacobian.col(0) + jacobian.col(1) + 1e-3 * noise;  // 1 − R² ≈ 1e-6 / 2
  EXPECT_TRUE(DependentColumns(Normal(jacobian)).empty());
  EXPECT_EQ(DependentColumns(Normal(jacobian), 1e-4).size(), 1u);
}

// r = x[0] + y[0] - 1 and r = x[1] - 2: only the sum x[0] + y[0] is determined.
struct SumResidual {
  template <typename T>
  bool operator()(const T* x, const T* y, T* residual) const {
    residual[0] = x[0] + y[0] - T(1);
    residual[1] = x[1] - T(2);
    return true;
  }
};

TEST(UndeterminedParameters, NamesTheBlockAndCoordinateThatOnlyASumDetermines) {
  double x[2] = {0, 0}, y[1] = {0}, fixed[1] = {3};
  ceres::Problem problem;
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<SumResidual, 2, 2, 1>(new SumResidual), nullptr, x, y);
  problem.AddParameterBlock(fixed, 1);
  problem.SetParameterBlockConstant(fixed);
  const std::vector<std::string> named = UndeterminedParameters(&problem, {{x, "x"}, {y, "y"}});
  ASSERT_EQ(named.size(), 1u);
  EXPECT_TRUE(named[0] == "x (tangent coordinates 0 of 2)" ||
              named[0] == "y (tangent coordinates 0 of 1)")
      << named[0];
  // With y's value given, everything is determined.
  problem.SetParameterBlockConstant(y);
  EXPECT_TRUE(UndeterminedParameters(&problem, {}).empty());
}

TEST(UndeterminedParameters, AnUnnamedBlockIsNamedByItsIndex) {
  double x[2] = {0, 0}, y[1] = {0};
  ceres::Problem problem;
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<SumResidual, 2, 2, 1>(new SumResidual), nullptr, x, y);
  const std::vector<std::string> named = UndeterminedParameters(&problem, {});
  ASSERT_EQ(named.size(), 1u);
  EXPECT_EQ(named[0].rfind("parameter block ", 0), 0u) << named[0];
}

// The blocks come with their pointers (so that a caller can act on them, e.g. remove a landmark)
// and the same description.
TEST(UndeterminedParameters, BlocksCarryTheirPointerCoordinatesAndSize) {
  double x[2] = {0, 0}, y[1] = {0};
  ceres::Problem problem;
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<SumResidual, 2, 2, 1>(new SumResidual), nullptr, x, y);
  const std::vector<UndeterminedBlock> blocks = UndeterminedBlocks(&problem);
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_TRUE(blocks[0].block == x || blocks[0].block == y);
  EXPECT_EQ(blocks[0].coordinates, std::vector<int>{0});
  EXPECT_EQ(blocks[0].tangent_size, blocks[0].block == x ? 2 : 1);
  EXPECT_EQ(DescribeUndetermined(blocks, {{x, "x"}, {y, "y"}}),
            UndeterminedParameters(&problem, {{x, "x"}, {y, "y"}}));
}

}  // namespace
}  // namespace colmap_lidar
