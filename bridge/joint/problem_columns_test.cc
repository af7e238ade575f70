#include "bridge/joint/problem_columns.h"

#include <ceres/autodiff_cost_function.h>
#include <gtest/gtest.h>

#include <array>
#include <vector>

namespace colmap_lidar {
namespace {

// An arrow Jacobian: every row holds the last column (as T_e's columns are coupled to every station)
// and one column of its own, in descending order, so that each row brings a new smallest row of
// JᵀJ's last column. This is the pattern on which Eigen 3.4's pruning product writes past its buffer.
Eigen::SparseMatrix<double> DescendingArrowJacobian(int num_cols) {
  std::vector<Eigen::Triplet<double>> triplets;
  for (int row = 0; row + 1 < num_cols; ++row) {
    triplets.emplace_back(row, num_cols - 2 - row, 1.0 + 0.001 * row);
    triplets.emplace_back(row, num_cols - 1, 2.0);
  }
  Eigen::SparseMatrix<double> jacobian(num_cols - 1, num_cols);
  jacobian.setFromTriplets(triplets.begin(), triplets.end());
  return jacobian;
}

TEST(NormalMatrix, EqualsTheDenseProductOnAnArrowWithADenseColumn) {
  const Eigen::SparseMatrix<double> jacobian = DescendingArrowJacobian(2000);
  const Eigen::SparseMatrix<double> normal = NormalMatrix(jacobian);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(jacobian).transpose() * Eigen::MatrixXd(jacobian);
  EXPECT_EQ((Eigen::MatrixXd(normal) - dense).cwiseAbs().maxCoeff(), 0.0);
  // The diagonal, the last row and the last column.
  EXPECT_EQ(normal.nonZeros(), 3 * 2000 - 2);
}

TEST(NormalMatrix, StoresNoEntryThatCancelsToZero) {
  Eigen::SparseMatrix<double> jacobian(2, 2);
  jacobian.insert(0, 0) = 1.0;
  jacobian.insert(0, 1) = 1.0;
  jacobian.insert(1, 0) = 1.0;
  jacobian.insert(1, 1) = -1.0;
  const Eigen::SparseMatrix<double> normal = NormalMatrix(jacobian);
  EXPECT_EQ(normal.nonZeros(), 2);
  EXPECT_EQ(normal.coeff(0, 0), 2.0);
  EXPECT_EQ(normal.coeff(1, 1), 2.0);
}

// r = a - b: a residual between two one-dimensional blocks.
struct DifferenceCost {
  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    residual[0] = a[0] - b[0];
    return true;
  }
  static ceres::CostFunction* Create() {
    return new ceres::AutoDiffCostFunction<DifferenceCost, 1, 1, 1>(new DifferenceCost);
  }
};

TEST(ParameterBlocksInResidualOrder, FollowsTheResidualsNotTheAddresses) {
  std::array<double, 5> values = {0, 1, 2, 3, 4};
  ceres::Problem problem;
  // Residuals chain the blocks from the highest address down; block 0 has no residual.
  for (int k = 4; k > 1; --k) {
    problem.AddResidualBlock(DifferenceCost::Create(), nullptr, &values[k], &values[k - 1]);
  }
  problem.AddParameterBlock(&values[0], 1);
  problem.SetParameterBlockConstant(&values[2]);
  const std::vector<double*> expected = {
      &values[4], &values[3], &values[2], &values[1], &values[0]};
  EXPECT_EQ(ParameterBlocksInResidualOrder(problem), expected);
  const ProblemColumns columns = FreeColumns(&problem);
  const std::vector<double*> free = {&values[4], &values[3], &values[1], &values[0]};
  EXPECT_EQ(columns.blocks, free);
  EXPECT_EQ(columns.first_column, (std::vector<int>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace colmap_lidar
