// Point-to-plane associations between two station clouds (used by the joint problem's LiDAR term):
// source points drawn at random, each paired with its nearest target point within a gate and that
// point's normal. The target's k-d tree is built once by the caller and reused across re-associations.
// Normal-space sampling (Rusinkiewicz & Levoy, "Efficient variants of the ICP algorithm", 2001) draws
// evenly over the source normals' directions, so that the few points on faces that constrain a
// direction (a wall's side, a pillar's flank) are not outnumbered by the ground.
#pragma once

#include "lidar/kd_tree.h"
#include "lidar/point_cloud.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace colmap_lidar {

// One observation of the LiDAR residual of Zhen et al. 2019: E_l = n^T (target_from_source * p - q) / sigma_l.
struct PointToPlaneObservation {
  Eigen::Vector3d point_in_source;   // p
  Eigen::Vector3d point_in_target;   // q
  Eigen::Vector3d normal_in_target;  // n, unit
};

struct AssociationOptions {
  // Source points drawn (without replacement).
  size_t num_samples = 2000;
  // Draw evenly over normal directions (needs source normals; uniform draws without them). Off by
  // default: it made the joint result worse on the simulated structures, as rare normals are mostly
  // curved or edge surfaces.
  bool normal_space_sampling = false;
  // gate on |T p - q| [m]
  double max_distance = 0.1;
  // only planar target neighbourhoods (if curvature is given)
  double max_curvature = 0.05;
  uint64_t seed = 0;

  bool Check() const;
};

// Per-point curvatures of the clouds of an association, each may be null: the target's keep only
// planar target neighbourhoods (none: no planarity filter); the source's restrict normal-space
// sampling to planar source points, whose normals are reliable.
struct AssociationCurvatures {
  const std::vector<double>* target = nullptr;
  const std::vector<double>* source = nullptr;
};

// `target` needs normals.
std::vector<PointToPlaneObservation> AssociatePointToPlane(
    const PointCloud& source,
    const PointCloud& target,
    const KdTree3& target_tree,
    const Eigen::Isometry3d& target_from_source,
    const AssociationOptions& options,
    const AssociationCurvatures& curvatures = {});

}  // namespace colmap_lidar
