// The LiDAR term E_l of one directed station pair (target i, source j) as ONE residual block with an
// analytic Jacobian: residual k is the paper's point-to-plane residual (joint cost, LiDAR term)
//
//   E_l,k = n_k^T (lidar_i_from_lidar_j p_k - q_k) / sigma_l,
//   lidar_i_from_lidar_j = inverse(T_e) * cam_i_from_world * inverse(cam_j_from_world) * T_e,
//
// the same function as LidarPointToPlaneCostFunctor (bridge/joint/lidar_point_to_plane_cost.h),
// which stays as the autodiff reference. One block per pair instead of one per observation: the cost of a solve
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
// Compressed (the default for more than 13 observations): with T = (R, t) = lidar_i_from_lidar_j, a
// reference T0 (the pair's transform when it was associated), p~_k = T0 p_k, their centroid c and
// p'_k = p~_k - c, every residual is linear in x = [vec(R R0^T - I) (row-major), T p0 - T0 p0, 1]
// (p0 = T0^-1 c, the source centroid):
//   r_k = a_k^T x,  a_k = [vec(n_k p'_k^T), n_k, n_k^T (p~_k - q_k)] / sigma.
// So sum_k r_k^2 = x^T M x with the 13x13 moment matrix M = sum_k a_k a_k^T, built once. With
// M = S^T S (S the R factor of A's QR decomposition) the block returns the 13 residuals S x: exactly the same cost, J^T J
// and J^T r as the N plain residuals, and a smooth function of the parameters (GradientChecker applies).
// An evaluation costs O(1) instead of O(N). Near T0, x is [small, small, 1]: no large terms cancel, so
// the cost keeps its precision far from the sensor.
#pragma once

#include "lidar/point_to_plane_association.h"

#include "colmap/geometry/rigid3.h"

#include <Eigen/Core>
#include <ceres/cost_function.h>

#include <vector>

namespace colmap_lidar {

class LidarPairPointToPlaneCost : public ceres::CostFunction {
 public:
  static constexpr int kCompressedResiduals = 13;
  using TangentJacobian = Eigen::Matrix<double, Eigen::Dynamic, 18, Eigen::RowMajor>;

  // `observations`: p in lidar_j, q and unit n in lidar_i; at least one. `reference`: the pair's
  // lidar_i_from_lidar_j near which it is solved (any transform is exact; a near one is precise).
  LidarPairPointToPlaneCost(std::vector<PointToPlaneObservation> observations,
                            double sigma,
                            bool compress,
                            const colmap::Rigid3d& reference);

  static ceres::CostFunction* Create(std::vector<PointToPlaneObservation> observations,
                                     double sigma,
                                     bool compress = true,
                                     const colmap::Rigid3d& reference = colmap::Rigid3d());

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
  void BuildMoments(const colmap::Rigid3d& reference);
  bool EvaluateCompressed(double const* const* parameters,
                          double* residuals,
                          double** jacobians) const;

  const std::vector<PointToPlaneObservation> observations_;
  const double inverse_sigma_;
  const bool compressed_;
  // Compressed form: R0^T, p0, T0 p0 and S with S^T S = M (see above).
  Eigen::Matrix3d reference_rotation_transposed_;
  Eigen::Vector3d source_centroid_;
  Eigen::Vector3d reference_centroid_;
  Eigen::Matrix<double, kCompressedResiduals, kCompressedResiduals, Eigen::RowMajor> square_root_;
};

}  // namespace colmap_lidar
