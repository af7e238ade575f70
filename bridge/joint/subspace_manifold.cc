#include "bridge/joint/subspace_manifold.h"

#include "colmap_ext/logging.h"

#include <Eigen/Eigenvalues>

#include <vector>

namespace colmap_lidar {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The eigenvectors of a projection whose eigenvalue is above (held) or below (free) one half.
Eigen::MatrixXd ProjectionEigenvectors(const Eigen::Matrix3d& projection, bool held) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(projection);
  std::vector<int> columns;
  for (int k = 0; k < 3; ++k) {
    if ((eigen.eigenvalues()[k] > 0.5) == held) columns.push_back(k);
  }
  Eigen::MatrixXd directions(3, static_cast<int>(columns.size()));
  for (size_t c = 0; c < columns.size(); ++c) {
    directions.col(static_cast<int>(c)) = eigen.eigenvectors().col(columns[c]);
  }
  return directions;
}

}  // namespace

SubspaceManifold::SubspaceManifold(std::unique_ptr<ceres::Manifold> base,
                                   const Eigen::MatrixXd& basis)
    : base_(std::move(base)), basis_(basis) {
  THROW_CHECK_EQ(basis_.rows(), base_->TangentSize());
  THROW_CHECK_GT(basis_.cols(), 0);
  THROW_CHECK_LE(basis_.cols(), basis_.rows());
  THROW_CHECK_LT(
      (basis_.transpose() * basis_ - Eigen::MatrixXd::Identity(basis_.cols(), basis_.cols()))
          .norm(),
      1e-9)
      << "the basis must have orthonormal columns";
}

bool SubspaceManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::VectorXd full = basis_ * Eigen::Map<const Eigen::VectorXd>(delta, basis_.cols());
  return base_->Plus(x, full.data(), x_plus_delta);
}

bool SubspaceManifold::PlusJacobian(const double* x, double* jacobian) const {
  RowMajorMatrix full(base_->AmbientSize(), base_->TangentSize());
  if (!base_->PlusJacobian(x, full.data())) return false;
  Eigen::Map<RowMajorMatrix>(jacobian, base_->AmbientSize(), basis_.cols()) = full * basis_;
  return true;
}

bool SubspaceManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::VectorXd full(base_->TangentSize());
  if (!base_->Minus(y, x, full.data())) return false;
  Eigen::Map<Eigen::VectorXd>(y_minus_x, basis_.cols()) = basis_.transpose() * full;
  return true;
}

bool SubspaceManifold::MinusJacobian(const double* x, double* jacobian) const {
  RowMajorMatrix full(base_->TangentSize(), base_->AmbientSize());
  if (!base_->MinusJacobian(x, full.data())) return false;
  Eigen::Map<RowMajorMatrix>(jacobian, basis_.cols(), base_->AmbientSize()) =
      basis_.transpose() * full;
  return true;
}

Eigen::MatrixXd FreeDirectionsBasis(const Eigen::Matrix3d& held_projection) {
  return ProjectionEigenvectors(held_projection, false);
}

Eigen::MatrixXd HeldDirectionsOf(const Eigen::Matrix3d& held_projection) {
  return ProjectionEigenvectors(held_projection, true);
}

}  // namespace colmap_lidar
