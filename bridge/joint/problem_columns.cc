#include "bridge/joint/problem_columns.h"

#include <unordered_set>

namespace colmap_lidar {

std::vector<double*> ParameterBlocksInResidualOrder(const ceres::Problem& problem) {
  std::vector<double*> ordered;
  ordered.reserve(problem.NumParameterBlocks());
  std::unordered_set<const double*> seen;
  std::vector<ceres::ResidualBlockId> residual_blocks;
  problem.GetResidualBlocks(&residual_blocks);
  std::vector<double*> blocks;
  for (const ceres::ResidualBlockId id : residual_blocks) {
    problem.GetParameterBlocksForResidualBlock(id, &blocks);
    for (double* block : blocks) {
      if (seen.insert(block).second) ordered.push_back(block);
    }
  }
  problem.GetParameterBlocks(&blocks);  // those without a residual block, by address
  for (double* block : blocks) {
    if (seen.insert(block).second) ordered.push_back(block);
  }
  return ordered;
}

ProblemColumns FreeColumns(ceres::Problem* problem) {
  ProblemColumns columns;
  for (double* block : ParameterBlocksInResidualOrder(*problem)) {
    if (problem->IsParameterBlockConstant(block)) continue;
    const int size = problem->ParameterBlockTangentSize(block);
    if (size == 0) continue;
    columns.first_column.push_back(static_cast<int>(columns.block_of_column.size()));
    columns.size.push_back(size);
    columns.block_of_column.insert(
        columns.block_of_column.end(), size, static_cast<int>(columns.blocks.size()));
    columns.blocks.push_back(block);
  }
  return columns;
}

Eigen::SparseMatrix<double> SparseJacobian(const ceres::CRSMatrix& jacobian) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(jacobian.values.size());
  for (int row = 0; row < jacobian.num_rows; ++row) {
    for (int k = jacobian.rows[row]; k < jacobian.rows[row + 1]; ++k) {
      triplets.emplace_back(row, jacobian.cols[k], jacobian.values[k]);
    }
  }
  Eigen::SparseMatrix<double> sparse(jacobian.num_rows, jacobian.num_cols);
  sparse.setFromTriplets(triplets.begin(), triplets.end());
  return sparse;
}

Eigen::SparseMatrix<double> NormalMatrix(const Eigen::SparseMatrix<double>& jacobian) {
  Eigen::SparseMatrix<double> normal = jacobian.transpose() * jacobian;
  normal.prune([](Eigen::Index, Eigen::Index, double value) { return value != 0.0; });
  return normal;
}

}  // namespace colmap_lidar
