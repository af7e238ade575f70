#include "bridge/joint/extrinsic_deviation_cost.h"

#include <Eigen/Cholesky>

#include <stdexcept>

namespace colmap_lidar {

Matrix6d WhiteningOfCovariance(const Matrix6d& covariance) {
  if (!covariance.allFinite() || !covariance.isApprox(covariance.transpose(), 1e-9)) {
    throw std::invalid_argument("an extrinsic covariance must be finite and symmetric");
  }
  const Eigen::LLT<Matrix6d> factor(covariance);
  if (factor.info() != Eigen::Success ||
      factor.matrixL().toDenseMatrix().diagonal().minCoeff() <= 0) {
    throw std::invalid_argument("an extrinsic covariance must be positive definite");
  }
  // covariance = L L^T, so W = L^-1 gives W^T W = L^-T L^-1 = covariance^-1.
  return factor.matrixL().solve(Matrix6d::Identity());
}

}  // namespace colmap_lidar
