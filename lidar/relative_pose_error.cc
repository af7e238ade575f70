#include "lidar/relative_pose_error.h"

#include <ceres/autodiff_cost_function.h>

namespace colmap_lidar {

ceres::CostFunction* RelativePoseError::Create(
    const Eigen::Isometry3d& target_from_source,
    const Eigen::Matrix<double, 6, 6>& sqrt_information) {
  return new ceres::AutoDiffCostFunction<RelativePoseError, 6, 4, 3, 4, 3>(
      new RelativePoseError(target_from_source, sqrt_information));
}

}  // namespace colmap_lidar
