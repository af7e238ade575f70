// Motion compensation ("de-skewing") of a rotating LiDAR's sweep taken from a moving platform (a car,
// a backpack). A sweep's points are measured over one revolution while the platform moves; read as one
// rigid cloud they are smeared by the motion (at 10 m/s and 10 Hz, up to 0.5 m either side of the
// sweep's middle). Each point is moved into the LiDAR frame at the middle of the sweep (fraction 0.5,
// where KITTI and the simulator take the frame's pose and trigger the camera), assuming constant
// velocity within each half of the sweep:
//
//   point_in_mid = mid_from_lidar(s) point,  s = fraction - 0.5,
//   mid_from_lidar(s) = (AngleAxis(|s| theta, axis), |s| t),  (theta, axis, t) of mid_from_next_mid
//   for s >= 0 (the next sweep's middle in this one's) and of mid_from_previous_mid for s < 0,
//
// where a point's fraction follows from its azimuth atan2(y, x) in the LiDAR frame: the revolution
// starts at `start_azimuth_deg` and turns counter-clockwise (about +z) unless told otherwise.
// Eigen-only header.
#pragma once

#include "lidar/point_cloud.h"

#include <Eigen/Geometry>

#include <utility>
#include <vector>

namespace colmap_lidar {

struct SweepTimingOptions {
  // Azimuth [deg] (LiDAR frame, x forward, y left) where a revolution starts; 180: behind the
  // platform, so that the middle of the sweep looks forward (KITTI, the simulator).
  double start_azimuth_deg = 180;
  bool counter_clockwise = true;

  bool Check() const;
};

// The fraction [0, 1) of the revolution at which a point in the LiDAR frame was measured.
double SweepFraction(const Eigen::Vector3d& point_in_lidar, const SweepTimingOptions& options);

// Each point's fraction [0, 1] of the sweep: from its time where the cloud carries per-point times
// ((t - earliest) / (latest - earliest), whatever their unit and origin), else from its azimuth
// (SweepFraction). Throws std::invalid_argument for times that do not time a sweep: all equal, or
// a few far outside the rest (the span of the middle 98 % is below 0.9 of the full span's 98 %).
std::vector<double> SweepFractions(const PointCloud& sweep, const SweepTimingOptions& options);

// Where a sweep began and ended: the middles of its neighbours in its own middle's frame. With one
// neighbour only, the other is its mirror (constant velocity).
struct SweepMotion {
  Eigen::Isometry3d mid_from_previous_mid = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d mid_from_next_mid = Eigen::Isometry3d::Identity();
};

// Each sweep's motion from the poses of its neighbours in time. Sweep i was taken at frame `frame[i]`
// (increasing) with pose world_from_lidar[i] at its middle in component `component[i]` (poses of
// different components are not comparable); the motion to a neighbour k frames away is divided by k.
// Without one neighbour the other is mirrored (constant velocity); without both, none (identity).
std::vector<SweepMotion> SweepMotionsFromPoses(
    const std::vector<Eigen::Isometry3d>& world_from_lidar,
    const std::vector<double>& frame,
    const std::vector<int>& component);

// Each sweep's middle in units of the median sweep duration, from the start and end time [s] of
// every sweep (a driver's timestamps): the `frame` of SweepMotionsFromPoses when frames are not
// evenly spaced (KITTI raw drops frames), so that the motion per sweep follows the clock. Throws
// std::invalid_argument for a sweep that does not end after it starts.
std::vector<double> SweepClockFromTimes(const std::vector<std::pair<double, double>>& start_end);

// The sweep in the LiDAR frame at its middle, each point moved by its SweepFractions; normals and
// times are not carried (they change with the points, and the points are no longer skewed).
PointCloud DeskewSweep(const PointCloud& sweep,
                       const SweepMotion& motion,
                       const SweepTimingOptions& options);

}  // namespace colmap_lidar
