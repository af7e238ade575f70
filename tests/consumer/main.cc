// Uses one call of each installed layer: prints "consumer ok" and exits 0 when they work.
#include "bridge/initialization/hand_eye.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/pose_graph.h"

#include <iostream>

int main() {
  using namespace colmap_lidar;
  // lidar: a two-node pose graph.
  Eigen::Isometry3d a_from_b = Eigen::Isometry3d::Identity();
  a_from_b.translation() = Eigen::Vector3d(1, 2, 3);
  const PoseGraphSolution graph =
      SolvePoseGraph(2, {{0, 1, a_from_b, 1.0, {}}}, PoseGraphOptions());
  // colmap_ext and bridge: COLMAP types through our headers, an options check.
  const colmap::Rigid3d pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 2, 3));
  const bool ok =
      graph.world_from_node[1].translation().isApprox(pose.translation) && HandEyeOptions().Check();
  std::cout << (ok ? "consumer ok" : "consumer FAILED") << std::endl;
  return ok ? 0 : 1;
}
