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
Eigen::SparseMatrix<double> NormalMatrix(ceres::Problem* problem, const ProblemColumns& columns) {
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = columns.blocks;
  double cost = 0;
  ceres::CRSMatrix crs;
  problem->Evaluate(options, &cost, nullptr, nullptr, &crs);
  const Eigen::SparseMatrix<double> jacobian = SparseJacobian(crs);
  return (jacobian.transpose() * jacobian).pruned();
}

std::string BlockName(const std::map<const double*, std::string>& names,
                      const double* block,
                      size_t index) {
  const auto name = names.find(block);
  return name != names.end() ? name->second : "parameter block " + std::to_string(index);
}

}  // namespace

std::vector<std::string> UndeterminedParameters(ceres::Problem* problem,
                                                const std::map<const double*, std::string>& names) {
  const ProblemColumns columns = FreeColumns(problem);
  if (columns.blocks.empty()) return {};
  const std::vector<int> dependent = DependentColumns(NormalMatrix(problem, columns));
  // Per block, its dependent tangent coordinates (`dependent` is ascending).
  std::map<int, std::string> coordinates;
  for (const int column : dependent) {
    const int block = columns.block_of_column[column];
    std::string& list = coordinates[block];
    list += (list.empty() ? "" : ", ") + std::to_string(column - columns.first_column[block]);
  }
  std::vector<std::string> undetermined;
  for (const auto& [block, list] : coordinates) {
    undetermined.push_back(BlockName(names, columns.blocks[block], block) +
                           " (tangent coordinates " + list + " of " +
                           std::to_string(columns.size[block]) + ")");
  }
  return undetermined;
}

}  // namespace colmap_lidar
