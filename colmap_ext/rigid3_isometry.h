// Conversions between COLMAP's Rigid3d (rotation quaternion + translation) and Eigen's Isometry3d (the
// lidar/ layer's pose type). Both represent the same target_from_source transform.
#pragma once

#include "colmap/geometry/rigid3.h"

#include <Eigen/Geometry>

namespace colmap_lidar {

inline Eigen::Isometry3d ToIsometry(const colmap::Rigid3d& target_from_source) {
  Eigen::Isometry3d isometry = Eigen::Isometry3d::Identity();
  isometry.linear() = target_from_source.rotation.toRotationMatrix();
  isometry.translation() = target_from_source.translation;
  return isometry;
}

inline colmap::Rigid3d ToRigid3d(const Eigen::Isometry3d& target_from_source) {
  return colmap::Rigid3d(Eigen::Quaterniond(target_from_source.linear()).normalized(),
                         target_from_source.translation());
}

}  // namespace colmap_lidar
