// The columns of a Ceres problem's Jacobian: its free parameter blocks in the problem's order, each
// with its tangent coordinates, and the Jacobian Ceres evaluates as an Eigen sparse matrix.
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

ProblemColumns FreeColumns(ceres::Problem* problem);

// `jacobian` (as ceres::Problem::Evaluate gives it) as an Eigen sparse matrix.
Eigen::SparseMatrix<double> SparseJacobian(const ceres::CRSMatrix& jacobian);

}  // namespace colmap_lidar
