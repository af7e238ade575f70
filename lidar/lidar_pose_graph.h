// All-pairs LiDAR registration and the LiDAR pose graph (A_l of Zhen et al. 2019): register station
// pairs, accept edges, for sweeps register edges whose speed contradicts their neighbours' again from
// the neighbours' velocity (or refuse them), remove edges inconsistent around 3-cycles, take a maximum
// spanning tree for initial poses, refine all poses over all accepted edges with Ceres
// (information-weighted, robust), and report the connected components. Station poses are
// world_from_lidar with the first station of each component as its world (identity).
#pragma once

#include "lidar/cycle_consistency.h"
#include "lidar/pair_registration.h"
#include "lidar/speed_consistency.h"
#include "lidar/station_cloud.h"

#include <Eigen/Geometry>

#include <functional>
#include <string>
#include <vector>

namespace colmap_lidar {

struct LidarEdge {
  size_t target = 0;                                                     // i
  size_t source = 0;                                                     // j
  Eigen::Isometry3d target_from_source = Eigen::Isometry3d::Identity();  // lidar_i_from_lidar_j
  PairRegistration registration;
  // An odometry's edge between consecutive frames: in a sweep pose graph it is weighted by the
  // odometry's drift model as well as by its registration (lidar/sweep_pose_graph.h).
  bool odometry = false;
  // Preference in the spanning tree: overlap * sqrt(constraint ratio) / RMSE.
  double Weight() const;
};

// Symmetric square root of an edge's information for the pose graph ([omega, t] in the target frame):
// the ICP Hessian scaled so that its best-held translation direction has information 1 / sigma^2
// (sigma: the pair's ICP RMSE), keeping its shape, so that a degenerate direction enters with the
// little information it has.
Eigen::Matrix<double, 6, 6> EdgeSqrtInformation(const PairRegistration& registration);

struct LidarGraphOptions {
  PairRegistrationOptions pair;
  // 0: register every pair. Otherwise each station is registered with its `max_neighbors` most
  // similar stations by a global descriptor (the histogram of its BSC bits), for large captures.
  size_t max_neighbors = 0;
  // > 0: also register each frame with its `sequential` successors (sweeps of a moving platform);
  // with max_neighbors = 0 only these pairs are registered.
  size_t sequential = 0;
  // When the accepted edges leave several components, each station outside the largest one is
  // registered with its `bridge_neighbors` most similar stations of the other components (pairs not
  // tried yet), for up to `max_bridge_rounds` rounds while the stations stay disconnected: bounded
  // by k per station, as the candidates are. Stations seen from another attitude (a tilted pod)
  // describe each other best and would otherwise form a component of their own.
  size_t bridge_neighbors = 4;
  int max_bridge_rounds = 2;
  // Remove edges inconsistent around 3-cycles before the spanning tree (CheckThreeCycles).
  bool check_cycles = true;
  CycleConsistencyOptions cycles;
  // Sweeps (frame indices given): first an edge whose speed contradicts the edges around it is
  // registered again from their velocity, and refused if that fails too.
  SpeedConsistencyOptions speed;
  // pose-graph refinement over all accepted edges
  bool refine = true;
  // Huber loss of the refinement, on residuals whitened by each edge's information (in sigmas).
  double robust_loss_sigmas = 3.0;

  bool Check() const;
};

struct LidarGraph {
  std::vector<LidarEdge> edges;    // accepted
  std::vector<LidarEdge> refused;  // attempted, not accepted (registration.reason says why)
  std::vector<Eigen::Isometry3d> world_from_lidar;  // per station
  std::vector<int> component;  // per station, 0-based; component 0 holds station 0
  int num_components = 0;
  size_t num_bridge_pairs = 0;  // pairs tried to join components (LidarGraphOptions)
  // Sweeps: edges registered again from the neighbours' velocity (LidarGraphOptions::speed), kept.
  size_t num_speed_reregistered = 0;
  double refinement_initial_cost = 0, refinement_final_cost = 0;
  // 3-cycles of the registered edges, and the worst loop error among those left after the check.
  size_t num_cycles = 0;
  double worst_cycle_translation_m = 0, worst_cycle_rotation_deg = 0;
};

// Progress: called after each pair with (pairs done, pairs total).
// `frame_indices`: for sweeps of a moving platform, each station's frame (time order, in frame
// periods), which turns on the speed check; empty for stations.
LidarGraph RegisterAllStations(const std::vector<const StationCloud*>& stations,
                               const LidarGraphOptions& options,
                               const std::function<void(size_t, size_t)>& progress = nullptr,
                               const std::vector<double>& frame_indices = {});

}  // namespace colmap_lidar
