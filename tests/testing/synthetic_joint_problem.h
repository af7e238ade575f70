// Test helpers around the synthetic joint problem (bridge/survey/synthetic_joint_problem.h).
#pragma once

#include "bridge/survey/synthetic_joint_problem.h"

#include "colmap/geometry/rigid3.h"

#include <Eigen/Core>

#include <cmath>

namespace colmap_lidar {
namespace testing {

using sim::MakeSyntheticJointProblem;
using sim::SyntheticJointOptions;
using sim::SyntheticJointProblem;

// Rotation error [deg] about the camera axes and translation error [mm] of an estimated cam_from_lidar,
// as the 6-vector the uncertainty reports (rotation vector of estimate * inverse(truth)).
inline Eigen::Matrix<double, 6, 1> ExtrinsicError(const colmap::Rigid3d& estimate,
                                                  const colmap::Rigid3d& truth) {
  Eigen::Matrix<double, 6, 1> error;
  const Eigen::AngleAxisd rotation(estimate.rotation * truth.rotation.inverse());
  error.head<3>() = rotation.angle() * rotation.axis() * 180 / M_PI;
  error.tail<3>() = 1000 * (estimate.translation - truth.translation);
  return error;
}

}  // namespace testing
}  // namespace colmap_lidar
