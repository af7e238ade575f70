// The rotation of cam_from_lidar about one camera-frame axis, searched over the whole turn from
// structure: camera-frame points (triangulated or stereo) against each station's own LiDAR cloud.
// A drive that never turns shows both sensors its direction of travel (so R_e maps the LiDAR's
// travel direction onto the camera's) but no rotation about it; what fixes that roll is the scene:
// the road and the facades seen by both sensors coincide at one roll only. For each candidate roll
// theta, R(theta) = Rot(axis, theta) R_start with the translation held at the start, every sampled
// point is moved into the LiDAR frame and scored by its distance to the nearest LiDAR point,
// truncated (a point with no LiDAR counterpart costs the same at every roll):
//   score(theta) = mean_k min(d_k(theta)^2, tau^2).
// The best roll is the start of a local alignment (lidar/extrinsic_alignment.h). The runner-up (the
// lowest other local minimum at least `min_separation_deg` away) says how distinct the best is.
#pragma once

#include "lidar/extrinsic_alignment.h"
#include "lidar/station_cloud.h"

#include <Eigen/Geometry>

#include <vector>

namespace colmap_lidar {

struct AxisRollSearchOptions {
  // candidate rolls every `step_deg` over [0, 360)
  double step_deg = 1.0;
  // points per station scored (an even stride through each station's points)
  int max_points_per_station = 400;
  // truncation tau of a point's distance [m]
  double truncation_m = 1.0;
  // a runner-up is at least this far from the best roll [deg]
  double min_separation_deg = 20.0;

  bool Check() const;
};

struct AxisRollSearchResult {
  Eigen::Isometry3d cam_from_lidar = Eigen::Isometry3d::Identity();  // at the best roll
  double best_roll_deg = 0;       // about the axis, from the start
  double best_rms_m = 0;          // sqrt of the best score
  double runner_up_roll_deg = 0;  // the lowest other local minimum, min_separation_deg away
  double runner_up_rms_m = 0;
  size_t num_points = 0;            // scored, all stations
  std::vector<double> rms_by_roll;  // sqrt(score) per candidate, roll k * step_deg
};

// `points[i]` belong to `clouds[i]` (with their k-d trees). `axis_in_cam` need not be unit. Throws
// std::invalid_argument on mismatched sizes, a zero axis, no points or bad options.
AxisRollSearchResult SearchRollAboutAxis(const std::vector<CameraDepthPoints>& points,
                                         const std::vector<const StationCloud*>& clouds,
                                         const Eigen::Isometry3d& start_cam_from_lidar,
                                         const Eigen::Vector3d& axis_in_cam,
                                         const AxisRollSearchOptions& options);

}  // namespace colmap_lidar
