// cam_from_lidar of a forward-looking camera on a car whose LiDAR has x forward and z up: camera
// x = -LiDAR y, camera y = -LiDAR z, tilted by `tilt_rad` about a generic axis and offset as on a
// car. Header-only, Eigen only.
#pragma once

#include <Eigen/Geometry>

namespace colmap_lidar {
namespace testing {

inline Eigen::Isometry3d CarCamFromLidar(double tilt_rad) {
  Eigen::Matrix3d axes;
  axes << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  Eigen::Isometry3d cam_from_lidar = Eigen::Isometry3d::Identity();
  cam_from_lidar.linear() =
      Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix() *
      axes;
  cam_from_lidar.translation() = Eigen::Vector3d(0.05, -0.08, -0.27);
  return cam_from_lidar;
}

}  // namespace testing
}  // namespace colmap_lidar
