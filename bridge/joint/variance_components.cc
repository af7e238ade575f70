#include "bridge/joint/variance_components.h"

#include "bridge/joint/problem_columns.h"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <ceres/cost_function.h>
#include <ceres/crs_matrix.h>

#include <algorithm>

namespace colmap_lidar {
namespace {

// Per parameter block and group (the last index: the fixed blocks), the diagonal block of J_g^T J_g.
using BlockInformation = std::vector<std::vector<Eigen::MatrixXd>>;

// Adds row `row` of the Jacobian (its entries in columns order) to the diagonal blocks of `group`.
void AddRow(const ceres::CRSMatrix& jacobian,
            int row,
            int group,
            const ProblemColumns& columns,
            BlockInformation* information) {
  const int begin = jacobian.rows[row], end = jacobian.rows[row + 1];
  for (int a = begin; a < end; ++a) {
    const int block = columns.block_of_column[jacobian.cols[a]];
    Eigen::MatrixXd& target = (*information)[block][group];
    if (target.size() == 0)
      target = Eigen::MatrixXd::Zero(columns.size[block], columns.size[block]);
    const int i = jacobian.cols[a] - columns.first_column[block];
    for (int b = begin; b < end; ++b) {
      if (columns.block_of_column[jacobian.cols[b]] != block) continue;
      target(i, jacobian.cols[b] - columns.first_column[block]) +=
          jacobian.values[a] * jacobian.values[b];
    }
  }
}

// tr(H_b^+ H_gb) for every group, summed over blocks: H_b's pseudo-inverse leaves out directions a
// block has no information in (they carry no parameter).
std::vector<double> ParameterShares(const BlockInformation& information, size_t num_groups) {
  std::vector<double> shares(num_groups, 0.0);
  for (const std::vector<Eigen::MatrixXd>& per_group : information) {
    Eigen::MatrixXd total;
    for (const Eigen::MatrixXd& h : per_group) {
      if (h.size() == 0) continue;
      total = total.size() == 0 ? h : Eigen::MatrixXd(total + h);
    }
    if (total.size() == 0) continue;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(total);
    const double tolerance = 1e-12 * std::max(eigen.eigenvalues().maxCoeff(), 0.0);
    Eigen::VectorXd inverse = Eigen::VectorXd::Zero(total.rows());
    for (int k = 0; k < total.rows(); ++k) {
      if (eigen.eigenvalues()[k] > tolerance) inverse[k] = 1.0 / eigen.eigenvalues()[k];
    }
    const Eigen::MatrixXd pseudo_inverse =
        eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
    for (size_t g = 0; g < num_groups; ++g) {
      if (per_group[g].size() > 0) shares[g] += (pseudo_inverse * per_group[g]).trace();
    }
  }
  return shares;
}

}  // namespace

std::vector<VarianceComponent> EstimateVarianceComponents(
    ceres::Problem* problem,
    const std::vector<VarianceGroup>& groups,
    const std::vector<ceres::ResidualBlockId>& fixed) {
  const ProblemColumns columns = FreeColumns(problem);
  std::vector<ceres::ResidualBlockId> blocks;
  std::vector<int> row_group;
  const auto add = [&](const std::vector<ceres::ResidualBlockId>& ids, int group) {
    for (const ceres::ResidualBlockId id : ids) {
      blocks.push_back(id);
      row_group.insert(
          row_group.end(), problem->GetCostFunctionForResidualBlock(id)->num_residuals(), group);
    }
  };
  for (size_t g = 0; g < groups.size(); ++g) add(groups[g].blocks, static_cast<int>(g));
  add(fixed, static_cast<int>(groups.size()));
  std::vector<VarianceComponent> components(groups.size());
  for (size_t g = 0; g < groups.size(); ++g) {
    components[g].name = groups[g].name;
    components[g].num_observations = groups[g].num_observations;
  }
  if (blocks.empty() || columns.blocks.empty()) return components;
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = columns.blocks;
  options.residual_blocks = blocks;
  double cost = 0;
  std::vector<double> residuals;
  ceres::CRSMatrix jacobian;
  problem->Evaluate(options, &cost, &residuals, nullptr, &jacobian);
  BlockInformation information(columns.blocks.size(),
                               std::vector<Eigen::MatrixXd>(groups.size() + 1));
  for (int row = 0; row < jacobian.num_rows; ++row) {
    AddRow(jacobian, row, row_group[row], columns, &information);
    if (row_group[row] < static_cast<int>(groups.size())) {
      components[row_group[row]].squared_norm += residuals[row] * residuals[row];
    }
  }
  const std::vector<double> shares = ParameterShares(information, groups.size() + 1);
  for (size_t g = 0; g < groups.size(); ++g) {
    VarianceComponent& component = components[g];
    component.parameter_share = shares[g];
    component.redundancy = static_cast<double>(component.num_observations) - shares[g];
    if (component.redundancy > 0.5)
      component.factor = component.squared_norm / component.redundancy;
  }
  return components;
}

}  // namespace colmap_lidar
