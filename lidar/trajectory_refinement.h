// Refinement of a sweep trajectory (an odometry's) at the resolution of the pairwise path: each
// frame is registered with its next `neighbors` frames by point-to-plane ICP (lidar/
// pair_registration.h RegisterFromGuess), started from the trajectory's relative pose, on clouds
// prepared without features (lidar/station_cloud.h); the pairwise gates judge each edge. The
// accepted edges replace the odometry's edges they duplicate (the same consecutive frames), the
// others stay, and the sweep pose graph (lidar/sweep_pose_graph.h) solves the poses. Clouds are read
// one at a time and kept only while a later frame still pairs with them.
#pragma once

#include "lidar/lidar_pose_graph.h"
#include "lidar/pair_registration.h"
#include "lidar/station_cloud.h"
#include "lidar/sweep_pose_graph.h"

#include <functional>
#include <string>
#include <vector>

namespace colmap_lidar {

struct TrajectoryRefinementOptions {
  // Each frame is registered with this many following frames.
  int neighbors = 2;
  StationCloudOptions cloud;  // compute_features is not used: no features are computed
  PairRegistrationOptions pair;
  OdometryDrift drift;

  bool Check() const;
};

struct TrajectoryRefinement {
  size_t num_pairs = 0;
  size_t num_accepted = 0;
  double seconds = 0;
};

// Refines graph->world_from_lidar (one pose per cloud of `cloud_paths`, edges the odometry's):
// accepted edges join graph->edges, refused ones graph->refused. Progress: (frames done, total).
TrajectoryRefinement RefineTrajectory(
    const std::vector<std::string>& cloud_paths,
    const TrajectoryRefinementOptions& options,
    LidarGraph* graph,
    const std::function<void(size_t, size_t)>& progress = nullptr);

}  // namespace colmap_lidar
