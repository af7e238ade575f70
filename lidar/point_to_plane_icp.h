// Point-to-plane ICP (Chen & Medioni 1992): Gauss-Newton on sum_i (n_i^T (T p_i - q_i))^2 over the
// source points whose nearest target point lies within a gate that shrinks from `max_correspondence_
// distance` towards six times the residual RMS (never below `min_correspondence_distance`). Given
// target curvatures, a second phase from the converged pose keeps that gate and uses the planar
// target points only (`max_target_curvature`).
#pragma once

#include "lidar/kd_tree.h"
#include "lidar/point_cloud.h"

#include <Eigen/Geometry>

#include <vector>

namespace colmap_lidar {

struct IcpOptions {
  int max_iterations = 50;
  // metres, first iteration
  double max_correspondence_distance = 0.3;
  // metres, the gate never shrinks below this
  double min_correspondence_distance = 0.05;
  // evenly strided subset of the source
  size_t max_source_points = 30000;
  // Converged when a step is below both and the gate has settled. Nearest neighbours keep
  // switching on noisy clouds, so steps settle around 1e-6 rather than at machine precision.
  double convergence_rotation_rad = 1e-6;
  double convergence_translation_m = 1e-5;
  // With target curvatures, the second phase: target points above this (edges, junctions, thin
  // cylinders, whose normals mix surfaces) enter no residual, only the overlap. Their residuals are
  // biased at the true pose: on a car's forward-moving sweeps they pitch every registration alike.
  // Leaving them out from the start loses the basin: a street's forward constraint comes mostly from
  // them.
  double max_target_curvature = 0.02;

  bool Check() const;
};

struct IcpResult {
  Eigen::Isometry3d target_from_source = Eigen::Isometry3d::Identity();
  bool converged = false;
  int iterations = 0;
  size_t num_inliers = 0;    // correspondences within the final gate
  double overlap_ratio = 0;  // num_inliers / source points used
  double rmse = 0;           // point-to-plane RMSE of the inliers [m]
  // sum J J^T over the final inliers, J = [p' x n; n]: the Gauss-Newton Hessian in [omega, t] (a left
  // increment of target_from_source in the target frame); and the RMS |p'| of those inliers [m].
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  double lever_arm_m = 0;
};

// The Gauss-Newton step of a point-to-plane problem as a transform: rotation by the rotation vector
// x[0..2] [rad], then translation x[3..5] [m] (a left increment, applied as step * pose).
Eigen::Isometry3d IsometryFromIncrement(const Eigen::Matrix<double, 6, 1>& x);

// The next iteration's association gate: shrunk towards six times the residual RMS, by at most 30 %
// per iteration, never below `min_gate`. An ICP has converged when its step is small and this gate
// has settled (above 0.98 of the current one).
double NextIcpGate(double gate, double residual_rms, double min_gate);

// `target` must have normals and `target_tree` must be built over target.points; `target_curvature`
// (one per target point, may be null: no filter) as EstimateNormals gives it.
IcpResult PointToPlaneIcp(const PointCloud& source,
                          const PointCloud& target,
                          const KdTree3& target_tree,
                          const Eigen::Isometry3d& initial_target_from_source,
                          const IcpOptions& options,
                          const std::vector<double>* target_curvature = nullptr);

}  // namespace colmap_lidar
