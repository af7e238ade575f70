// cam_from_lidar from image edges and LiDAR depth discontinuities: the baseline of Levinson & Thrun
// ("Automatic Online Calibration of Cameras and Lasers", RSS 2013) that the paper's joint optimisation
// is compared with. Per station, the LiDAR's depth discontinuities (lidar/depth_discontinuities.h)
// are projected into the left image's inverse distance transform of its edges
// (colmap_ext/edge_distance_transform.h); the objective
//   J(T_e) = sum over stations, sum over discontinuity points p of X_p D(project(T_e p))
// is maximised by a grid search: the 3^6 grid of +-1 step about the current estimate, move to the best,
// repeat until the centre is best, then the next (finer) step; F_c is the share of the 728 neighbours
// with a lower J at the end (Levinson & Thrun's own confidence). No camera poses are needed: each
// station is its own image and cloud.
#pragma once

#include "colmap_ext/edge_distance_transform.h"
#include "lidar/depth_discontinuities.h"

#include <colmap/geometry/rigid3.h>
#include <colmap/scene/camera.h>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace colmap_lidar {

struct EdgeCalibrationOptions {
  // Per station; max_points keeps the strongest discontinuities (they carry nearly all of J).
  DepthDiscontinuityOptions discontinuities = [] {
    DepthDiscontinuityOptions options;
    options.max_points = 20000;
    return options;
  }();
  EdgeDistanceTransformOptions transform;
  // The coarse-to-fine schedule: grid steps of rotation [deg] and translation [m], one pair per level.
  std::vector<double> rotation_steps_deg = {1.0, 0.5, 0.2, 0.1};
  std::vector<double> translation_steps_m = {0.05, 0.03, 0.02, 0.01};
  // Grid moves per level at most.
  int max_moves_per_level = 30;
  // Points nearer than this in front of the camera are not projected [m].
  double min_depth_m = 0.3;

  bool Check() const;
};

// What the objective needs of one station: the inverse distance transform of its left image's edges,
// the camera (any COLMAP model) and the cloud's depth discontinuities in the LiDAR frame.
struct EdgeStation {
  std::string name;
  cv::Mat transform;  // CV_32F D
  colmap::Camera camera;
  std::vector<DepthDiscontinuity> discontinuities;
};

EdgeStation PrepareEdgeStation(const std::string& name,
                               const cv::Mat& image,
                               const colmap::Camera& camera,
                               const std::vector<Eigen::Vector3d>& points_in_lidar,
                               const EdgeCalibrationOptions& options);

// One station's share of J(T_e).
double StationEdgeObjective(const EdgeStation& station,
                            const colmap::Rigid3d& cam_from_lidar,
                            double min_depth_m);

// J(T_e): the X-weighted sum of D at the projected discontinuity points.
double EdgeObjective(const std::vector<EdgeStation>& stations,
                     const colmap::Rigid3d& cam_from_lidar,
                     double min_depth_m);

struct EdgeCalibrationResult {
  colmap::Rigid3d cam_from_lidar;
  double initial_objective = 0;
  double final_objective = 0;
  // F_c: share of the 728 grid neighbours (finest step) with a lower J than the result.
  double fraction_lower = 0;
  // Grid moves per level.
  std::vector<int> moves;
  // J after each move (the first entry: the start).
  std::vector<double> objective_history;
  bool converged = true;  // every level ended with its centre best (not at max_moves_per_level)
  double seconds = 0;
};

EdgeCalibrationResult CalibrateFromEdges(const std::vector<EdgeStation>& stations,
                                         const colmap::Rigid3d& initial_cam_from_lidar,
                                         const EdgeCalibrationOptions& options);

// The station's D (grey) with its discontinuity points projected through `before` (red) and `after`
// (green), for a person to look at.
cv::Mat EdgeOverlay(const EdgeStation& station,
                    const colmap::Rigid3d& before,
                    const colmap::Rigid3d& after,
                    double min_depth_m);

}  // namespace colmap_lidar
