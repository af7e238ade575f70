// Revisit (loop-closure) edges for a LiDAR odometry trajectory. Keyframes are taken every
// `keyframe_spacing_m` of path; a keyframe near an earlier frame in space (within `search_radius_m`
// by the odometry's positions) but far from it along the path (at least `min_path_gap_m`) is
// registered to the nearest such frame by BSC + RANSAC + ICP (lidar/pair_registration.h), independently of the odometry. The
// registration is accepted only when it agrees with the odometry within the odometry's drift: a
// chi-square test (6 degrees of freedom) of the difference between the two relative poses against
// the sum of their covariances. The odometry's covariance comes from a drift model, a systematic
// error per metre travelled in rotation and translation carried along the path (a rotation error
// early on moves every later position); the per-frame ICP covariances are lower bounds that leave
// out this correlation. Accepted revisits and the trajectory's edges then enter the robust pose
// graph (lidar/sweep_pose_graph.h).
#pragma once

#include "lidar/lidar_pose_graph.h"
#include "lidar/pair_registration.h"
#include "lidar/station_cloud.h"
#include "lidar/sweep_pose_graph.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace colmap_lidar {

struct RevisitOptions {
  double keyframe_spacing_m = 5.0;
  // Keyframes nearer than this (odometry positions) are registered: BSC finds the overlap of
  // sweeps taken up to about this far apart.
  double search_radius_m = 10.0;
  // Path between the two keyframes of a revisit: shorter gaps are the odometry's own neighbours.
  double min_path_gap_m = 50.0;
  // The odometry's drift: the chi-square test's covariance and the pose graph's weights.
  OdometryDrift drift;
  // Chi-square bound of an accepted revisit (6 degrees of freedom; 22.46: probability 0.999).
  double max_chi2 = 22.46;
  StationCloudOptions cloud;
  PairRegistrationOptions pair;

  bool Check() const;
};

struct RevisitEdge {
  LidarEdge edge;    // target: the earlier keyframe
  double chi2 = -1;  // against the odometry's drift; -1 where the registration itself failed
};

struct RevisitClosure {
  size_t num_keyframes = 0;
  size_t num_candidates = 0;
  std::vector<RevisitEdge> accepted, refused;
  double seconds = 0;
};

// Frame pairs (earlier, later) to register: each keyframe with its nearest earlier frame within the
// search radius and at least min_path_gap_m back along the path. `num_keyframes`
// (optional) receives the number of keyframes.
std::vector<std::pair<size_t, size_t>> RevisitCandidates(
    const std::vector<Eigen::Isometry3d>& world_from_lidar,
    const RevisitOptions& options,
    size_t* num_keyframes = nullptr);

// Covariance of the trajectory's relative pose target_from_source (target < source) under the drift
// model: [omega, t] of a left increment in the target frame (lidar/relative_pose_error.h).
Eigen::Matrix<double, 6, 6> DriftCovariance(const std::vector<Eigen::Isometry3d>& world_from_lidar,
                                            size_t target,
                                            size_t source,
                                            const RevisitOptions& options);

// Chi-square of a registered edge (target < source) against the trajectory's relative pose.
double RevisitChi2(const std::vector<Eigen::Isometry3d>& world_from_lidar,
                   const LidarEdge& edge,
                   const RevisitOptions& options);

// Finds, registers and tests the revisits of the trajectory `graph` (one pose per cloud, its edges
// the odometry's), reading the clouds of the keyframes involved from `cloud_paths`. Accepted
// revisits are added to graph->edges, refused ones to graph->refused, and the poses are solved
// again over all edges; without an accepted revisit the poses stay. Progress: (done, total) pairs.
RevisitClosure CloseRevisits(const std::vector<std::string>& cloud_paths,
                             const RevisitOptions& options,
                             LidarGraph* graph,
                             const std::function<void(size_t, size_t)>& progress = nullptr);

}  // namespace colmap_lidar
