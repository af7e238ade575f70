// The pose graph of a sweep trajectory: an odometry's edges between consecutive frames and edges
// measured by registration (revisits, refined neighbours) in the robust pose graph
// (lidar/pose_graph.h). An odometry edge's covariance is its step's drift under the drift model
// plus its registration's; a measured edge's is its registration's (EdgeSqrtInformation). The
// odometry's edges are preferred by the spanning tree, so that the refinement starts from their
// chain.
#pragma once

#include "lidar/lidar_pose_graph.h"
#include "lidar/pair_registration.h"

#include <Eigen/Core>

namespace colmap_lidar {

// An odometry's drift (1 sigma): a systematic error per metre travelled.
struct OdometryDrift {
  double translation = 0.01;          // [m/m]
  double rotation_deg_per_m = 0.005;  // [deg/m]

  // The diagonal covariance [omega, t] of the error per metre.
  Eigen::Matrix<double, 6, 6> PerMetre() const;
  bool Check() const;
};

// The covariance [omega, t] of a registration from its pose-graph information
// (EdgeSqrtInformation); directions without information get a variance far above any drift
// instead of an infinite one.
Eigen::Matrix<double, 6, 6> RegistrationCovariance(const PairRegistration& registration);

// Solves graph->world_from_lidar over graph->edges (odometry edges: LidarEdge::odometry).
void SolveSweepPoseGraph(const OdometryDrift& drift, LidarGraph* graph);

}  // namespace colmap_lidar
