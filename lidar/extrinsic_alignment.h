// cam_from_lidar from structure alone: camera-frame points with a depth (a stereo depth map,
// back-projected) aligned with each station's own LiDAR cloud, one shared extrinsic for all stations.
// Point-to-plane ICP (Chen & Medioni 1992) summed over the stations,
//   min over lidar_from_cam of  sum_i sum_k rho( n^T (lidar_from_cam * point_in_cam_ik - q) / sigma_ik ),
// with q, n the nearest planar sample of station i's cloud, and sigma_ik the point's depth noise
// projected on n (a stereo depth is uncertain along its ray) added in quadrature to the LiDAR noise.
// No station pose enters: unlike a hand-eye it needs no motion, so a car that only turns about its
// vertical axis gets the roll about its driving direction and the height from the road and the
// facades. A direction the scenes do not constrain (a single plane) stays at the start through a weak
// prior, and the reported sigmas say so.
#pragma once

#include "lidar/station_cloud.h"

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace colmap_lidar {

struct ExtrinsicAlignmentOptions {
  // association gate of the first iteration [m]; it shrinks towards 6 times the residual RMS
  double max_correspondence_distance_m = 1.0;
  // the gate never shrinks below this [m]
  double min_correspondence_distance_m = 0.1;
  int max_iterations = 50;
  // only LiDAR samples with a planar neighbourhood (StationCloud::curvature at most this)
  double max_curvature = 0.05;
  // LiDAR range noise [m], added in quadrature to each point's depth sigma along the normal (the pose
  // initialiser passes the rig's, rig.json lidar.range_noise_m)
  double sigma_lidar_m = 0.02;
  // Huber threshold in sigma units: residuals beyond it count linearly (edges, moving objects)
  double huber_sigmas = 2.0;
  // Directions whose information is below this fraction of the strongest's (rotations scaled by the
  // points' lever arm) are held at the start: between the tangent directions of a single floor
  // (noise in the LiDAR normals, well below) and the weakest direction of a room or a street drive
  // (several times above).
  double min_constraint_ratio = 0.001;
  // A weak prior on the start (1 sigma): what no scene constrains stays where it was.
  double prior_rotation_deg = 5.0;
  double prior_translation_m = 0.5;
  // converged when a step is below both and the gate has settled
  double convergence_rotation_deg = 1e-4;
  double convergence_translation_m = 1e-5;
  // With at least this many stations with associations, the covariance is clustered by station (a
  // sandwich over the stations' scores); with fewer, the formal one (independent residuals).
  int min_station_clusters = 10;
  // Relative error of every depth's scale, common to all stations (a stereo baseline or focal length
  // off, a sub-pixel bias): a consider parameter added to the covariance (as the joint's
  // ObservabilityOptions::stereo_scale_sigma); 0: none.
  double depth_scale_sigma = 0.001;

  bool Check() const;
};

// One station's camera-frame points: point_in_cam[k] with the 1-sigma error of its depth along its
// viewing ray, sigma_along_ray_m[k] (stereo: d^2 / (b f) sigma_p).
struct CameraDepthPoints {
  std::vector<Eigen::Vector3d> point_in_cam;
  std::vector<double> sigma_along_ray_m;
};

struct ExtrinsicAlignmentResult {
  Eigen::Isometry3d cam_from_lidar = Eigen::Isometry3d::Identity();
  bool converged = false;
  int iterations = 0;
  size_t num_points = 0;        // camera points offered, all stations
  size_t num_associations = 0;  // within the final gate on a planar LiDAR sample
  double rms_m = 0;             // point-to-plane RMS of the associations [m]
  double rms_sigmas = 0;        // the same in units of each residual's sigma
  // Covariance of cam_from_lidar: rotation [rad] about the camera's axes (a rotation vector left of
  // the rotation, R = exp(w) R_0), then translation [m] along them. Clustered by station when
  // `station_clustered` (residuals of one station share errors: its stereo biases and its cloud's
  // normals); else the formal one from the Gauss-Newton Hessian scaled by the residual variance,
  // which treats every residual as independent (a lower bound). A direction the scenes do not
  // constrain gets the prior's variance. Both include a depth scale error common to every station
  // (options.depth_scale_sigma).
  Eigen::Matrix<double, 6, 6> covariance_in_cam = Eigen::Matrix<double, 6, 6>::Zero();
  bool station_clustered = false;
  int num_station_clusters = 0;  // stations with associations
  // Its square roots on the diagonal, in degrees and metres.
  Eigen::Vector3d sigma_rotation_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_translation_m = Eigen::Vector3d::Zero();
  // Eigenvalues of the data's information in [rotation * lever arm, translation], weakest first,
  // over the strongest; the first `num_weak_directions` were held at the start.
  Eigen::Matrix<double, 6, 1> constraint_ratios = Eigen::Matrix<double, 6, 1>::Zero();
  int num_weak_directions = 0;
};

// `points[i]` belong to `clouds[i]` (normals, curvature and k-d tree as PrepareStationCloud builds
// them). Throws std::invalid_argument on mismatched sizes or bad options.
ExtrinsicAlignmentResult AlignCameraPointsWithLidar(const std::vector<CameraDepthPoints>& points,
                                                    const std::vector<const StationCloud*>& clouds,
                                                    const Eigen::Isometry3d& initial_cam_from_lidar,
                                                    const ExtrinsicAlignmentOptions& options);

}  // namespace colmap_lidar
