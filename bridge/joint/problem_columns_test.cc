#include "bridge/joint/problem_columns.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace colmap_lidar
