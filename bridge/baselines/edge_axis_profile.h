// The edge objective of bridge/baselines/edge_calibration.h along one rotation axis: J(exp(a u)
// T_e) for angles a about a unit axis u in the camera frame, per station, and where it peaks. A moving platform's
// T_e is weakest in its roll about the direction of travel (docs/mono.md), and the image edges see
// it directly (a LiDAR edge 10 m to the side moves by 17 mm per 0.1 deg of that roll). The peak's uncertainty is a
// bootstrap over stations (each station's image and cloud are one independent draw), not the
// curvature of J, whose points are not independent.
#pragma once

#include "bridge/baselines/edge_calibration.h"

#include <Eigen/Core>
#include <colmap/geometry/rigid3.h>

#include <cstdint>
#include <vector>

namespace colmap_lidar {

struct EdgeAxisProfileOptions {
  // The angles a in [-half_range_deg, half_range_deg] in steps of step_deg.
  double half_range_deg = 0.6;
  double step_deg = 0.01;
  // Bootstrap resamples of the stations for sigma_deg.
  int num_bootstrap = 400;
  uint64_t seed = 1;
  // Points nearer than this in front of the camera are not projected [m].
  double min_depth_m = 0.3;

  bool Check() const;
};

struct EdgeAxisProfile {
  Eigen::Vector3d axis_in_cam = Eigen::Vector3d::UnitZ();
  std::vector<double> angles_deg;
  // J summed over the stations at each angle.
  std::vector<double> objective;
  // The parabola vertex through the best angle and its two neighbours [deg].
  double peak_deg = 0;
  // Standard deviation of the peak over bootstrap resamples of the stations, times sqrt(n / (n - 1))
  // [deg]; 0 for one station.
  double sigma_deg = 0;
  // The peak lies at either end of the range: the true maximum may lie beyond it.
  bool at_range_end = false;
};

// The profile about `axis_in_cam` (normalised here) through `cam_from_lidar`: each angle a gives
// exp(a u) * cam_from_lidar (turned on the camera side, as calibrate_edges' grid).
EdgeAxisProfile ProfileEdgeObjective(const std::vector<EdgeStation>& stations,
                                     const colmap::Rigid3d& cam_from_lidar,
                                     const Eigen::Vector3d& axis_in_cam,
                                     const EdgeAxisProfileOptions& options);

// cam_from_lidar turned by `angle_deg` about `axis_in_cam` on the camera side.
colmap::Rigid3d TurnAboutCameraAxis(const colmap::Rigid3d& cam_from_lidar,
                                    const Eigen::Vector3d& axis_in_cam,
                                    double angle_deg);

}  // namespace colmap_lidar
