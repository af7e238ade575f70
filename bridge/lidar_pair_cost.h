// The LiDAR term E_l of one directed station pair (target i, source j) as ONE residual block with an
// analytic Jacobian: residual k is the paper's point-to-plane residual (joint cost, LiDAR term)
//
//   E_l,k = n_k^T (lidar_i_from_lidar_j p_k - q_k) / sigma_l,
//   lidar_i_from_lidar_j = inverse(T_e) * cam_i_from_world * inverse(cam_j_from_world) * T_e,
//
// the same function as LidarPointToPlaneCostFunctor (bridge/lidar_point_to_plane_cost.h), which stays
// as the autodiff reference. One block per pair instead of one per observation: the cost of a solve
// follows the number of pairs and samples, not the number of blocks, and a pair is the cluster of the
// cluster-robust covariance anyway.
//
// Parameter blocks (COLMAP's layout): cam_i_from_world rotation [4] (Eigen quaternion, xyzw) and
// translation [3], cam_j_from_world rotation [4] and translation [3], cam_from_lidar rotation [4] and
// translation [3]. Quaternion Jacobians are given for Ceres' EigenQuaternionManifold (the manifold COLMAP
// sets): J_ambient = J_tangent P^T with P = PlusJacobian (P^T P = I for a unit quaternion), so that
// J_ambient P = J_tangent. The manifold's tangent delta rotates by 2|delta| (q_delta = (cos|delta|,
// sin|delta| delta/|delta|)), hence J_tangent = 2 J_rotation_vector.
//
// Compressed (the default for more than 19 observations): the block returns 18 + 1 residuals whose
// Jacobian R and values r' satisfy R^T R = J^T J, R^T r' = J^T r and |r'|^2 + e^2 = |r|^2 (see the .cc):
// Ceres sees the same cost, gradient and Gauss-Newton model, but forms its normal equations from 19 rows
// per pair instead of thousands. Such residuals are not a smooth function of the parameters (only their
// linearisation at the evaluation point is), so GradientChecker applies to the plain form only; the
// tests compare the two forms' cost, J^T J and J^T r.
#pragma once

#include "lidar/point_to_plane_association.h"

#include <Eigen/Core>
#include <ceres/cost_function.h>

#include <vector>

namespace colmap_lidar {

class LidarPairPointToPlaneCost : public ceres::CostFunction {
 public:
  static constexpr int kCompressedResiduals = 19;
  using TangentJacobian = Eigen::Matrix<double, Eigen::Dynamic, 18, Eigen::RowMajor>;

  // `observations`: p in lidar_j, q and unit n in lidar_i; at least one.
  LidarPairPointToPlaneCost(std::vector<PointToPlaneObservation> observations,
                            double sigma,
                            bool compress);

  static ceres::CostFunction* Create(std::vector<PointToPlaneObservation> observations,
                                     double sigma,
                                     bool compress = true);

  // The plain residuals (one per observation) and, if asked, their Jacobian in the tangent space of the
  // six blocks (3 columns each, quaternion tangents as Ceres' manifold defines them).
  void Linearize(double const* const* parameters,
                 Eigen::VectorXd* residuals,
                 TangentJacobian* jacobian) const;

  int NumObservations() const { return static_cast<int>(observations_.size()); }

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

 private:
  const std::vector<PointToPlaneObservation> observations_;
  const double inverse_sigma_;
  const bool compressed_;
};

}  // namespace colmap_lidar
