// Depth discontinuities of a LiDAR cloud, the LiDAR side of the edge-based calibration of Levinson &
// Thrun ("Automatic Online Calibration of Cameras and Lasers", RSS 2013): along each scan line, a point
// gets X_i = max(r_{i-1} - r_i, r_{i+1} - r_i, 0)^gamma from the ranges r of its neighbours, so a
// point in front of its neighbours (the near side of a depth edge) scores and the far side does not.
//
// The scan lines are recovered from the points themselves (a station's accumulated cloud has no
// firing order): the rows of a spherical range image (lidar/spherical_range_image.h); a point's
// neighbours along the line are the nearest occupied cells left and right in its row within
// max_gap_cells.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace colmap_lidar {

struct DepthDiscontinuityOptions {
  // Cell size of the range image in elevation and azimuth [deg]; 0: the cell of one point if the
  // cloud's points were spread evenly over the elevations they cover, times 1.5 (most cells occupied).
  double angular_resolution_deg = 0.0;
  // The exponent gamma of X (Levinson & Thrun: 0.5).
  double gamma = 0.5;
  // Points with X at least this are kept (0.3 m^0.5 in published reimplementations: a 9 cm step).
  double min_score = 0.3;
  // Beyond Levinson & Thrun's X: a surface seen at a grazing angle steps away from the sensor from
  // cell to cell without any edge (at 20 m and 80 deg incidence, 0.3 m per 0.16 deg). A point counts
  // only if, over context_cells cells on each side, its own surface continues on the near side (each
  // within max_slope_ratio * step of its range) and the far side stays at least step / 2 farther.
  double max_slope_ratio = 0.25;
  int context_cells = 3;
  // Neighbours along the row are looked for at most this many cells away (empty cells between: no
  // return, or a gap of the sampling).
  int max_gap_cells = 3;
  // Points nearer than this (the platform itself) are left out [m].
  double min_range_m = 0.5;
  // At most this many points are returned, the highest scores (0: all).
  size_t max_points = 0;

  bool Check() const;
};

struct DepthDiscontinuity {
  Eigen::Vector3d point_in_lidar;
  double score = 0;  // X_i
};

// `points_in_lidar`: the cloud in its sensor's frame (the origin is the sensor). Sorted by score,
// highest first.
std::vector<DepthDiscontinuity> DetectDepthDiscontinuities(
    const std::vector<Eigen::Vector3d>& points_in_lidar, const DepthDiscontinuityOptions& options);

}  // namespace colmap_lidar
