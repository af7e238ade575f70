// Consistency of the LiDAR pose graph's edges around 3-cycles: for stations i, j, k with edges i-j, j-k
// and k-i, the composed loop lidar_i_from_lidar_j * lidar_j_from_lidar_k * lidar_k_from_lidar_i must be
// the identity. A wrong edge (ICP slid along a street, a repeated structure) breaks every cycle it is
// in; a right edge closes at least one. Edges are removed worst first (the most broken cycles and no
// closed one) until every remaining edge that lies on a cycle lies on a closed one. Two edges between
// the same stations (an image edge and a LiDAR edge of one motion) form a 2-cycle, checked alike.
#pragma once

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace colmap_lidar {

struct CycleConsistencyOptions {
  // A 3-cycle closes when its loop transform is within both tolerances.
  double max_translation_m = 0.15;
  double max_rotation_deg = 1.0;

  bool Check() const;
};

struct RelativePose {
  size_t target = 0;
  size_t source = 0;
  Eigen::Isometry3d target_from_source = Eigen::Isometry3d::Identity();
  double weight = 1;  // support; among equally broken edges the weakest goes first
};

struct CycleCheck {
  std::vector<bool> removed;        // per edge
  std::vector<std::string> reason;  // per edge: why it was removed (empty if kept)
  size_t num_cycles = 0;            // 3-cycles of the input edges
  // Largest loop error over the 3-cycles of the kept edges.
  double worst_translation_m = 0;
  double worst_rotation_deg = 0;
};

CycleCheck CheckThreeCycles(const std::vector<RelativePose>& edges,
                            const CycleConsistencyOptions& options);

}  // namespace colmap_lidar
