#include "bridge/joint/problem_columns.h"

namespace colmap_lidar {

ProblemColumns FreeColumns(ceres::Problem* problem) {
  ProblemColumns columns;
  std::vector<double*> blocks;
  problem->GetParameterBlocks(&blocks);
  for (double* block : blocks) {
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
