#include "bridge/joint/undetermined_parameters.h"

#include "bridge/joint/problem_columns.h"

#include <Eigen/SparseCholesky>
#include <ceres/crs_matrix.h>

namespace colmap_lidar {

std::vector<int> DependentColumns(const Eigen::SparseMatrix<double>& normal_matrix,
                                  double max_relative_pivot) {
  const int n = static_cast<int>(normal_matrix.cols());
  const Eigen::VectorXd diagonal = normal_matrix.diagonal();
  // Empty columns become identity columns (their rows are empty too: the matrix is semi-definite),
  // and every column gets a relative jitter far below the threshold, so that the factorisation
  // runs to the end and a dependent column shows as a tiny pivot instead of stopping it.
  Eigen::SparseMatrix<double> jittered = normal_matrix;
  constexpr double kJitter = 1e-14;
  for (int i = 0; i < n; ++i) {
    jittered.coeffRef(i, i) += diagonal[i] > 0 ? kJitter * diagonal[i] : 1.0;
  }
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(jittered);
  std::vector<int> dependent;
  for (int i = 0; i < n; ++i) {
    if (!(diagonal[i] > 0)) {
      dependent.push_back(i);
      continue;
    }
    const double pivot = ldlt.vectorD()[ldlt.permutationP().indices()[i]];
    if (!(pivot > max_relative_pivot * diagonal[i])) dependent.push_back(i);
  }
  return dependent;
}

namespace {

// JᵀJ of `problem` over the tangent coordinates of `columns`.
Eigen::SparseMatrix<double> EvaluatedNormalMatrix(ceres::Problem* problem,
                                                  const ProblemColumns& columns) {
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = columns.blocks;
  double cost = 0;
  ceres::CRSMatrix crs;
  problem->Evaluate(options, &cost, nullptr, nullptr, &crs);
  return NormalMatrix(SparseJacobian(crs));
}

std::string BlockName(const std::map<const double*, std::string>& names,
                      const double* block,
                      size_t index) {
  const auto name = names.find(block);
  return name != names.end() ? name->second : "parameter block " + std::to_string(index);
}

}  // namespace

std::vector<UndeterminedBlock> UndeterminedBlocks(ceres::Problem* problem) {
  const ProblemColumns columns = FreeColumns(problem);
  if (columns.blocks.empty()) return {};
  std::vector<UndeterminedBlock> blocks;
  for (const int column : DependentColumns(EvaluatedNormalMatrix(problem, columns))) {  // ascending
    const int block = columns.block_of_column[column];
    if (blocks.empty() || blocks.back().index != block) {
      blocks.push_back({columns.blocks[block], block, columns.size[block], {}});
    }
    blocks.back().coordinates.push_back(column - columns.first_column[block]);
  }
  return blocks;
}

std::vector<std::string> DescribeUndetermined(const std::vector<UndeterminedBlock>& blocks,
                                              const std::map<const double*, std::string>& names) {
  std::vector<std::string> undetermined;
  for (const UndeterminedBlock& block : blocks) {
    std::string list;
    for (const int coordinate : block.coordinates) {
      list += (list.empty() ? "" : ", ") + std::to_string(coordinate);
    }
    undetermined.push_back(BlockName(names, block.block, block.index) + " (tangent coordinates " +
                           list + " of " + std::to_string(block.tangent_size) + ")");
  }
  return undetermined;
}

std::vector<std::string> UndeterminedParameters(ceres::Problem* problem,
                                                const std::map<const double*, std::string>& names) {
  return DescribeUndetermined(UndeterminedBlocks(problem), names);
}

}  // namespace colmap_lidar
