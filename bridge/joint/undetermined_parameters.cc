#include "bridge/joint/undetermined_parameters.h"

#include <Eigen/SparseCholesky>
#include <ceres/crs_matrix.h>

#include <sstream>

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

// JᵀJ of `problem` over `blocks` (their tangent coordinates, in that order).
Eigen::SparseMatrix<double> NormalMatrix(ceres::Problem* problem,
                                         const std::vector<double*>& blocks) {
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = blocks;
  options.apply_loss_function = true;
  double cost = 0;
  ceres::CRSMatrix crs;
  problem->Evaluate(options, &cost, nullptr, nullptr, &crs);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(crs.values.size());
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) {
      triplets.emplace_back(row, crs.cols[k], crs.values[k]);
    }
  }
  Eigen::SparseMatrix<double> jacobian(crs.num_rows, crs.num_cols);
  jacobian.setFromTriplets(triplets.begin(), triplets.end());
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
  std::vector<double*> all_blocks;
  problem->GetParameterBlocks(&all_blocks);
  std::vector<double*> blocks;
  std::vector<int> first_column;
  int num_columns = 0;
  for (double* block : all_blocks) {
    if (problem->IsParameterBlockConstant(block)) continue;
    blocks.push_back(block);
    first_column.push_back(num_columns);
    num_columns += problem->ParameterBlockTangentSize(block);
  }
  const std::vector<int> dependent = DependentColumns(NormalMatrix(problem, blocks));
  std::vector<std::string> undetermined;
  size_t next = 0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const int size = problem->ParameterBlockTangentSize(blocks[b]);
    std::ostringstream coordinates;
    for (; next < dependent.size() && dependent[next] < first_column[b] + size; ++next) {
      coordinates << (coordinates.tellp() > 0 ? ", " : "") << dependent[next] - first_column[b];
    }
    if (coordinates.tellp() == 0) continue;
    undetermined.push_back(BlockName(names, blocks[b], b) + " (tangent coordinates " +
                           coordinates.str() + " of " + std::to_string(size) + ")");
  }
  return undetermined;
}

}  // namespace colmap_lidar
