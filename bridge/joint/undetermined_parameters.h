// Which parameters a least-squares problem leaves undetermined: the columns of its normal matrix
// JᵀJ that the other columns reproduce (nearly) exactly. A sparse LDLᵀ factorisation eliminates the
// columns one by one; column i's pivot D_i is its information left after the columns eliminated
// before it, so D_i / (JᵀJ)_ii = 1 − R² of column i regressed on them. A relative pivot below
// kMaxRelativePivot (or an empty column) means the data determine that coordinate only together
// with others: the normal matrix is singular to working precision, the linear solver of a
// Levenberg–Marquardt step fails on it ("not positive definite"), and no step along it is
// meaningful. Which column of a dependent set is named depends on the elimination order; the set is
// what the problem leaves undetermined.
#pragma once

#include <Eigen/SparseCore>
#include <ceres/problem.h>

#include <map>
#include <string>
#include <vector>

namespace colmap_lidar {

// 1 − R² below which a column counts as reproduced by the others: a conditional variance 1e10 times
// the column's own, far below what any measurement determines and far above double rounding.
inline constexpr double kMaxRelativePivot = 1e-10;

// Indices of the columns of the symmetric positive semi-definite `normal_matrix` whose relative
// pivot is below `max_relative_pivot`, ascending; an all-zero column is always among them.
std::vector<int> DependentColumns(const Eigen::SparseMatrix<double>& normal_matrix,
                                  double max_relative_pivot = kMaxRelativePivot);

// A free parameter block of a problem with undetermined tangent coordinates.
struct UndeterminedBlock {
  const double* block = nullptr;
  int index = 0;  // among the problem's free blocks
  int tangent_size = 0;
  std::vector<int> coordinates;  // ascending
};

// The free parameter blocks of `problem` with undetermined coordinates at their current values, in
// the order of the problem's free blocks.
std::vector<UndeterminedBlock> UndeterminedBlocks(ceres::Problem* problem);

// One entry per block: "<name> (tangent coordinates 0, 2 of 3)". `names` names the blocks; a block
// without a name is "parameter block <index>".
std::vector<std::string> DescribeUndetermined(const std::vector<UndeterminedBlock>& blocks,
                                              const std::map<const double*, std::string>& names);

// DescribeUndetermined(UndeterminedBlocks(problem), names).
std::vector<std::string> UndeterminedParameters(ceres::Problem* problem,
                                                const std::map<const double*, std::string>& names);

}  // namespace colmap_lidar
