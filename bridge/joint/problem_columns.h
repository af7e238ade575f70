// The columns of a Ceres problem's Jacobian: its free parameter blocks in a reproducible order, each
// with its tangent coordinates, the Jacobian Ceres evaluates as an Eigen sparse matrix, and its
// normal matrix.
#pragma once

#include <Eigen/SparseCore>
#include <ceres/crs_matrix.h>
#include <ceres/problem.h>

#include <vector>

namespace colmap_lidar {

// The free (not constant, tangent size > 0) parameter blocks and, per Jacobian column, its block.
struct ProblemColumns {
  std::vector<double*> blocks;
  std::vector<int> block_of_column;
  std::vector<int> first_column;  // per block
  std::vector<int> size;          // per block (tangent size)
};

// The problem's parameter blocks in the order its residual blocks (in the order they were added)
// first use them, then those no residual block uses. Not ceres::Problem::GetParameterBlocks, which
// lists them by address: addresses change from run to run with the heap (threads allocate from their
// own arenas), and sums and sparse orderings over columns in that order would change in their last
// digits.
std::vector<double*> ParameterBlocksInResidualOrder(const ceres::Problem& problem);

// The free blocks of ParameterBlocksInResidualOrder with their columns.
ProblemColumns FreeColumns(ceres::Problem* problem);

// `jacobian` (as ceres::Problem::Evaluate gives it) as an Eigen sparse matrix.
Eigen::SparseMatrix<double> SparseJacobian(const ceres::CRSMatrix& jacobian);

// Jᵀ J without stored zeros: Eigen's plain sparse product, pruned in place. Not Eigen 3.4's pruning
// product (`(A * B).pruned()`): its sparse work list for a result column has no capacity check when
// an entry arrives ahead of all it holds, so a column with many entries arriving in descending order
// (T_e's columns, coupled to every station) is written past its buffer and the heap is corrupted.
Eigen::SparseMatrix<double> NormalMatrix(const Eigen::SparseMatrix<double>& jacobian);

}  // namespace colmap_lidar
