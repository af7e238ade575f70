// Poses for cost-function unit tests: generic (no axis-aligned rotation, translation on every axis),
// so that no Jacobian entry is zero by accident.
#pragma once

#include "colmap/geometry/rigid3.h"

namespace colmap_lidar {
namespace testing {

inline colmap::Rigid3d Pose(double angle,
                            const Eigen::Vector3d& axis,
                            const Eigen::Vector3d& translation) {
  return colmap::Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized())),
                         translation);
}

// Two cameras and a cam_from_lidar for the LiDAR residual's tests.
struct GenericStationPair {
  colmap::Rigid3d cam_i_from_world = Pose(0.6, {0.2, -0.9, 0.4}, {0.3, -0.2, 1.9});
  colmap::Rigid3d cam_j_from_world = Pose(-1.1, {0.7, 0.3, -0.5}, {-0.8, 0.4, 2.4});
  colmap::Rigid3d cam_from_lidar = Pose(2.0, {0.4, -0.5, 0.6}, {0.19, -0.25, -0.05});

  // The six parameter blocks in the LiDAR cost functions' order.
  std::vector<double*> Blocks() {
    return {cam_i_from_world.rotation.coeffs().data(),
            cam_i_from_world.translation.data(),
            cam_j_from_world.rotation.coeffs().data(),
            cam_j_from_world.translation.data(),
            cam_from_lidar.rotation.coeffs().data(),
            cam_from_lidar.translation.data()};
  }
};

}  // namespace testing
}  // namespace colmap_lidar
