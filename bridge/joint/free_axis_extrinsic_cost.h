// A cost that sees cam_from_lidar turned by an angle of its own about a fixed camera axis u:
//
//   inner(..., exp(rho u) * T_e),   T_e = cam_from_lidar, rho a parameter block of size 1,
//
// so that the inner term says nothing about T_e's rotation about u (rho absorbs it) while every other
// direction of T_e is constrained as before: the cost is unchanged under
// (T_e, rho) -> (exp(delta u) T_e, rho - delta).
//
// Used for the LiDAR term E_l on a moving platform that turns about one axis: E_l constrains T_e only
// through the relative motions (hand-eye, AX = XB), and its information about the rotation about the
// driving direction comes from how the turns' axis maps between camera and LiDAR alone. With turns of
// a few degrees a drift of 0.001 deg per frame in either trajectory moves that rotation by tenths of a
// degree, so the rotation about the driving direction is left to the terms that see it directly
// (E_m: the landmarks on the LiDAR surfaces of their own station, or the stereo alignment).
//
// Layout: the inner cost's last two parameter blocks are T_e's rotation (Eigen quaternion, x y z w,
// with Ceres' EigenQuaternionManifold) and translation; this cost has the same blocks and rho last.
// The inner cost's quaternion Jacobians may be tangent-projected (J_tangent P^T, as
// bridge/joint/lidar_pair_cost.h gives them): every derivative taken here is along the unit sphere.
#pragma once

#include <Eigen/Core>
#include <ceres/cost_function.h>

#include <memory>

namespace colmap_lidar {

class FreeAxisExtrinsicCost : public ceres::CostFunction {
 public:
  // Takes ownership of `inner`. `axis_in_cam`: u, any length > 0 (normalised here).
  FreeAxisExtrinsicCost(ceres::CostFunction* inner, const Eigen::Vector3d& axis_in_cam);

  static ceres::CostFunction* Create(ceres::CostFunction* inner,
                                     const Eigen::Vector3d& axis_in_cam);

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

 private:
  std::unique_ptr<ceres::CostFunction> inner_;
  const Eigen::Vector3d axis_;
  const int num_inner_blocks_;
};

}  // namespace colmap_lidar
