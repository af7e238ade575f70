// A pose graph over relative-pose edges: initial poses from a maximum-weight spanning tree (Prim, from
// the first node of each connected component), then a Ceres refinement over every edge with a robust
// loss on the whitened residuals (relative_pose_error.h), the first node of each component held as the
// gauge. One module for the LiDAR pose graph A_l (lidar_pose_graph.h) and the camera pose graph
// A_c v A_l of the initialisation (bridge/initialization/pose_initializer.h). Poses are
// world_from_node; an edge measures target_from_source, so
// world_from_source = world_from_target * target_from_source.
#pragma once

#include "lidar/robust_loss.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace colmap_lidar {

struct RelativePoseEdge {
  size_t target = 0;  // i
  size_t source = 0;  // j
  Eigen::Isometry3d target_from_source = Eigen::Isometry3d::Identity();
  // Preference in the spanning tree (larger first).
  double weight = 0;
  // Whitening of [rotation; translation] residuals (relative_pose_error.h).
  Eigen::Matrix<double, 6, 6> sqrt_information = Eigen::Matrix<double, 6, 6>::Identity();
};

// W = diag(1/sigma_rotation x3, 1/sigma_translation x3) for independent errors.
Eigen::Matrix<double, 6, 6> DiagonalSqrtInformation(double sigma_rotation_rad,
                                                    double sigma_translation_m);

struct PoseGraphOptions {
  // Refine the spanning-tree poses over all edges (false: the tree's poses only).
  bool refine = true;
  // Robust loss of the refinement on the whitened residuals: Huber or Cauchy (not none).
  RobustLoss loss = RobustLoss::kHuber;
  // Its scale, in sigmas of the whitened residual.
  double loss_scale = 3.0;
  int max_num_iterations = 100;

  bool Check() const;
};

struct PoseGraphSolution {
  std::vector<Eigen::Isometry3d> world_from_node;  // identity at each component's first node
  std::vector<int> component;                      // per node, 0-based; component 0 holds node 0
  int num_components = 0;
  double initial_cost = 0, final_cost = 0;  // of the refinement (0 without one)
};

// Nodes 0 .. num_nodes - 1; edges whose target or source is out of range are refused (throws).
PoseGraphSolution SolvePoseGraph(size_t num_nodes,
                                 const std::vector<RelativePoseEdge>& edges,
                                 const PoseGraphOptions& options);

}  // namespace colmap_lidar
