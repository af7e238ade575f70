// One frame registered to the local map of LiDAR odometry (Vizzo et al., "KISS-ICP", RA-L 2023,
// Sec. III-E): point-to-point ICP with the Geman-McClure kernel, Gauss-Newton on a left increment
// dx = [omega, t] (world frame: x <- R(omega) x + t),
//   min sum_i rho(|T p_i - q_i|),  rho'(e) / e = kappa^2 / (kappa + e^2)^2,   (Eq. 7-8)
// q_i the nearest map point of T p_i within `max_correspondence_m` (tau), kappa = sigma / 3.
// With FrameToMapIcpOptions::point_to_plane (the default), the residual is the distance to the
// map's local plane (the map points within one voxel size of the nearest one, spanning several
// scan lines) where that neighbourhood is a plane, point-to-point where it is scattered, and there
// is none where it is the arc of one scan line or holds too few points to tell (the far ground
// and facades of a map of one or a few sweeps): a platform moving along flat ground and facades
// sees their rings and scan lines where it saw them before, so nearest points on these surfaces
// match best with no motion at all and would hold the ICP at the previous pose.
// After convergence the frame's information is measured point-to-plane (the map voxels' planes): a
// point-to-point Hessian is isotropic in translation whatever the geometry and cannot show a street
// of facades or a tunnel; the planes can.
// Sums run over fixed chunks of the points and are combined in chunk order: the result does not
// depend on the number of threads.
#pragma once

#include "lidar/voxel_hash_map.h"

#include <Eigen/Geometry>

#include <vector>

namespace colmap_lidar {

struct FrameToMapIcpOptions {
  int max_iterations = 500;
  // |dx| below which the iteration stops (rad and m together, as KISS-ICP).
  double convergence = 1e-4;
  // Point-to-plane residuals where the map around the nearest point is a plane, none where it is
  // one scan line's arc, point-to-point elsewhere; false: point-to-point everywhere (KISS-ICP).
  bool point_to_plane = true;

  bool Check() const;
};

struct FrameToMapIcpResult {
  Eigen::Isometry3d world_from_lidar = Eigen::Isometry3d::Identity();
  int num_iterations = 0;
  bool converged = false;
  size_t num_correspondences = 0;  // of the last iteration
  double rms_m = 0;                // point-to-point RMS of the last iteration's correspondences
  // Point-to-plane information in the LiDAR frame, [omega, t] of a right increment T Exp(dx), from
  // the correspondences whose map voxel holds a plane; its residual RMS; and the covariance
  // plane_rms^2 H^-1 (independent residuals assumed: a lower bound, points of one surface are
  // not independent).
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  size_t num_plane_correspondences = 0;
  double plane_rms_m = 0;
};

// `points_in_lidar` (already de-skewed and subsampled) against `map`, from `initial`; the map's
// points stay as they are, it keeps the shapes of their neighbourhoods for later frames. Throws
// std::invalid_argument for invalid options or a non-positive threshold or kernel.
FrameToMapIcpResult AlignFrameToMap(const std::vector<Eigen::Vector3d>& points_in_lidar,
                                    VoxelHashMap* map,
                                    const Eigen::Isometry3d& initial,
                                    double max_correspondence_m,
                                    double kernel_m,
                                    const FrameToMapIcpOptions& options);

}  // namespace colmap_lidar
