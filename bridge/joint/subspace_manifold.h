// Directions of a parameter held at their current value by removing them from its tangent space:
// Plus(x, delta) = base.Plus(x, B delta), with B (tangent size x m, orthonormal columns) spanning the
// free directions of the base manifold's tangent. A held direction is then exactly constant and is
// not a column of the problem's Jacobian, so a covariance of the free directions needs no tight prior
// and no huge information standing in for "known".
// Used for cam_from_lidar: its rotation on Ceres' EigenQuaternionManifold (left-multiplied tangent,
// rotating by 2|delta|) and its translation on a Euclidean manifold, each with the directions the data
// do not determine (or the user holds) removed.
#pragma once

#include <Eigen/Core>
#include <ceres/manifold.h>

#include <memory>

namespace colmap_lidar {

class SubspaceManifold : public ceres::Manifold {
 public:
  // `basis`: base.TangentSize() x m with orthonormal columns, 0 < m <= base.TangentSize().
  SubspaceManifold(std::unique_ptr<ceres::Manifold> base, const Eigen::MatrixXd& basis);

  int AmbientSize() const override { return base_->AmbientSize(); }
  int TangentSize() const override { return static_cast<int>(basis_.cols()); }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

 private:
  const std::unique_ptr<ceres::Manifold> base_;
  const Eigen::MatrixXd basis_;
};

// Orthonormal columns spanning the complement of the directions of `held_projection` (a sum of d d^T
// over orthonormal held directions d): 3 x (3 - number held), in a fixed order.
Eigen::MatrixXd FreeDirectionsBasis(const Eigen::Matrix3d& held_projection);

// The unit directions of `held_projection` (3 x number held, as columns).
Eigen::MatrixXd HeldDirectionsOf(const Eigen::Matrix3d& held_projection);

}  // namespace colmap_lidar
