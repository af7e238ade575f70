// A trajectory with known errors for tests of trajectory metrics: each step's motion recomposed with
// its translation scaled and a turn proportional to its length added. Header-only.
#pragma once

#include "colmap/geometry/rigid3.h"

#include <vector>

namespace colmap_lidar {
namespace testing {

// world_from_sensor poses whose every step has its translation times `scale` and a rotation of
// `deg_per_m` times its length about the sensor's `axis` (before the step's own rotation).
inline std::vector<colmap::Rigid3d> DistortedTrajectory(
    const std::vector<colmap::Rigid3d>& world_from_sensor,
    double scale,
    double deg_per_m,
    const Eigen::Vector3d& axis) {
  std::vector<colmap::Rigid3d> distorted = {world_from_sensor.front()};
  for (size_t k = 1; k < world_from_sensor.size(); ++k) {
    colmap::Rigid3d step = colmap::Inverse(world_from_sensor[k - 1]) * world_from_sensor[k];
    const double length = step.translation.norm();
    step.translation *= scale;
    step.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(deg_per_m * length * M_PI / 180, axis)) *
                    step.rotation;
    distorted.push_back(distorted.back() * step);
  }
  return distorted;
}

}  // namespace testing
}  // namespace colmap_lidar
