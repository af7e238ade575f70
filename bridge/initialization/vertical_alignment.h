// A measurement of cam_from_lidar's tilt from the vertical structure both sensors see (not part of
// Zhen et al. 2019). Per station, the vertical in the LiDAR frame is the direction perpendicular to
// the walls' normals (planar samples), and in the camera frame the direction perpendicular to the
// interpretation planes of the near-vertical image segments (lidar/perpendicular_direction.h). Then
// R_e up_in_lidar_i = up_in_cam_i for every station i, which fixes R_e's rotation about the two axes
// perpendicular to the vertical: for a forward-looking camera on a car, the roll about the driving
// direction (which a drive turning about one axis hardly shows to the motion-based terms) and the
// pitch. Assumes walls and vertical edges are plumb; structure that leans shows as station scatter,
// which enters the reported covariance (a random effect per station, inflated for the serial
// correlation of neighbouring stations).
#pragma once

#include "colmap_ext/image_line_segments.h"
#include "lidar/perpendicular_direction.h"
#include "lidar/point_cloud.h"

#include "colmap/scene/camera.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace colmap_lidar {

// PerpendicularDirectionOptions whose first gate is `initial_max_angle_deg`, in 8 iterations.
inline PerpendicularDirectionOptions WideGate(double initial_max_angle_deg) {
  PerpendicularDirectionOptions options;
  options.initial_max_angle_deg = initial_max_angle_deg;
  options.num_iterations = 8;
  return options;
}

struct VerticalAlignmentOptions {
  // Wide first gates: on a drive the guesses come from noisy turn axes and a hand-eye whose roll can
  // be degrees off. A gate narrower than the guess's error leaves the walls
  // out and fits whatever lies near perpendicular, consistently wrong at every station; the ground
  // (normal along the vertical) stays out of any gate below 50 deg.
  PerpendicularDirectionOptions lidar_fit = WideGate(35);
  PerpendicularDirectionOptions camera_fit = WideGate(20);
  LineSegmentOptions segments;
  // LiDAR samples above this curvature are not walls
  double max_curvature = 0.02;
  // stations whose residual is beyond this Mahalanobis distance (squared, 2 dof) are left out once
  double max_station_chi2 = 13.8;
  size_t min_num_stations = 5;

  bool Check() const;
};

// One station's input, borrowed for the call.
struct VerticalStationInput {
  std::string name;
  std::string image_path;
  const colmap::Camera* camera = nullptr;
  // point_in_lidar with normals; `curvature` per point
  const PointCloud* cloud = nullptr;
  const std::vector<double>* curvature = nullptr;
};

struct StationVertical {
  std::string name;
  PerpendicularDirection up_in_lidar;
  PerpendicularDirection up_in_cam;
  size_t num_segments = 0;
  bool used = false;
  // R_e up_in_lidar - up_in_cam at the result, on the measured `axes` of VerticalAlignment [deg]
  Eigen::Vector2d residual_deg = Eigen::Vector2d::Zero();
};

struct VerticalAlignment {
  bool valid = false;
  std::string message;  // why not valid, or a one-line summary
  // camera-frame axes perpendicular to the mean vertical: the two directions measured
  Eigen::Matrix<double, 3, 2> axes = Eigen::Matrix<double, 3, 2>::Zero();
  // the correction omega = axes * alpha to apply as cam_from_lidar <- exp(omega) cam_from_lidar
  Eigen::Vector2d correction = Eigen::Vector2d::Zero();  // alpha [rad]
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  // of alpha [rad^2]
  // per-station structure variance added to each station's own (random effect) [rad^2]
  double station_variance = 0;
  // Lag-1 autocorrelation of the station residuals in capture order (the larger of the two axes,
  // at least 0): neighbouring stations see the same walls and edges, so a structure that is not
  // plumb shifts a run of stations alike. `covariance` is inflated by (1 + rho) / (1 - rho), the
  // variance of a mean of AR(1) errors, at most to that of a single station.
  double serial_correlation = 0;
  double effective_stations = 0;  // stations used / that inflation
  std::vector<StationVertical> stations;

  // Whether the correction differs from zero at 95 % (alpha^T covariance^-1 alpha > chi2_2).
  bool Significant() const;

  // exp(axes * correction) * cam_from_lidar_rotation
  Eigen::Quaterniond Corrected(const Eigen::Quaterniond& cam_from_lidar_rotation) const;
  // Covariance of the corrected rotation about the camera axes [rad^2]: `covariance` along `axes`,
  // `unmeasured_variance` about the vertical.
  Eigen::Matrix3d RotationCovariance(double unmeasured_variance) const;
};

// `up_in_lidar_guess`: the vertical's rough direction in the LiDAR frame (e.g. a drive's common turn
// axis); the camera's guess is cam_from_lidar_rotation times the station's LiDAR vertical. Stations
// in parallel (OpenMP).
VerticalAlignment MeasureVerticalAlignment(const std::vector<VerticalStationInput>& stations,
                                           const Eigen::Quaterniond& cam_from_lidar_rotation,
                                           const Eigen::Vector3d& up_in_lidar_guess,
                                           const VerticalAlignmentOptions& options);

}  // namespace colmap_lidar
