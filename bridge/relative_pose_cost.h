// A pose-graph edge: the measured relative pose cam_i_from_cam_j against the estimated poses
// (COLMAP's layout: cam_from_world rotation as Eigen quaternion xyzw, translation):
//
//   E = [ 2 vec(q_meas^-1 * q_i * q_j^-1) / sigma_rotation ; (t_i - R_i R_j^T t_j - t_meas) / sigma_translation ]
#pragma once

#include "colmap/estimators/cost_functions.h"
#include "colmap/geometry/rigid3.h"

#include <ceres/autodiff_cost_function.h>

namespace colmap_lidar {

class RelativePoseCostFunctor {
 public:
  RelativePoseCostFunctor(const colmap::Rigid3d& cam_i_from_cam_j,
                          double sigma_rotation_rad,
                          double sigma_translation_m)
      : measured_(cam_i_from_cam_j),
        inverse_sigma_rotation_(1.0 / sigma_rotation_rad),
        inverse_sigma_translation_(1.0 / sigma_translation_m) {}

  static ceres::CostFunction* Create(const colmap::Rigid3d& cam_i_from_cam_j,
                                     double sigma_rotation_rad,
                                     double sigma_translation_m) {
    return new ceres::AutoDiffCostFunction<RelativePoseCostFunctor, 6, 4, 3, 4, 3>(
        new RelativePoseCostFunctor(cam_i_from_cam_j, sigma_rotation_rad, sigma_translation_m));
  }

  template <typename T>
  bool operator()(const T* const rotation_i,
                  const T* const translation_i,
                  const T* const rotation_j,
                  const T* const translation_j,
                  T* residuals) const {
    const Eigen::Quaternion<T> q_i = colmap::EigenQuaternionMap<T>(rotation_i);
    const Eigen::Quaternion<T> q_j = colmap::EigenQuaternionMap<T>(rotation_j);
    const Eigen::Quaternion<T> i_from_j = q_i * q_j.conjugate();
    const Eigen::Quaternion<T> error = measured_.rotation.cast<T>().conjugate() * i_from_j;
    const Eigen::Matrix<T, 3, 1> t_i_from_j = colmap::EigenVector3Map<T>(translation_i) -
                                              i_from_j * colmap::EigenVector3Map<T>(translation_j);
    for (int k = 0; k < 3; ++k) {
      residuals[k] = T(2) * error.vec()[k] * T(inverse_sigma_rotation_);
      residuals[3 + k] =
          (t_i_from_j[k] - T(measured_.translation[k])) * T(inverse_sigma_translation_);
    }
    return true;
  }

 private:
  const colmap::Rigid3d measured_;
  const double inverse_sigma_rotation_;
  const double inverse_sigma_translation_;
};

}  // namespace colmap_lidar
