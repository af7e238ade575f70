// The sweeps of a moving platform registered by LiDAR odometry (lidar/lidar_odometry.h) into the
// LiDAR pose graph's result type: every frame a pose in one world (the first frame's), and an edge
// between consecutive frames carrying the odometry's relative motion, its point-to-plane information
// and its constraint analysis. Clouds are read one at a time (streamed: a drive of thousands of
// sweeps never sits in memory).
#pragma once

#include "lidar/lidar_odometry.h"
#include "lidar/lidar_pose_graph.h"

#include <functional>
#include <string>
#include <vector>

namespace colmap_lidar {

struct OdometryRegistration {
  LidarGraph graph;
  std::vector<OdometryFrame> frames;
  double seconds_registering = 0;  // the odometry alone, without reading the files
};

// `clock`: each sweep's middle in sweep durations (lidar/sweep_deskew.h SweepClockFromTimes, or the
// frame indices), increasing. Progress: called after each frame with (frames done, total). Throws
// std::runtime_error naming the file of a cloud that cannot be read or has no point in range.
OdometryRegistration RegisterSweepsByOdometry(
    const std::vector<std::string>& cloud_paths,
    const std::vector<double>& clock,
    const LidarOdometryOptions& options,
    const std::function<void(size_t, size_t)>& progress = nullptr);

}  // namespace colmap_lidar
