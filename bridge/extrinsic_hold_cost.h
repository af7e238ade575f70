// Holds chosen directions of cam_from_lidar at their initial value (not part of the cost of Zhen et al.
// 2019): when the joint solve finds directions of T_e unobservable, they are held where they started
// (the guess or the hand-eye) instead of drifting along them. With P_r, P_t the projections onto the held
// rotation and translation directions (sums of d d^T over unit directions in the camera frame):
//
//   E_h = [P_r rotvec(R R_0^-1); P_t (t - t_0)] / sigma    (6 residuals, rows of zero where nothing is held)
//
// with a tiny sigma, so that the held directions are effectively constant and the others free.
// Parameter blocks (COLMAP's layout): cam_from_lidar rotation [4] (Eigen quaternion, xyzw) and
// translation [3].
#pragma once

#include "colmap/estimators/cost_functions.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

namespace colmap_lidar {

class ExtrinsicHoldCostFunctor {
 public:
  ExtrinsicHoldCostFunctor(const Eigen::Quaterniond& initial_rotation,
                           const Eigen::Vector3d& initial_translation,
                           const Eigen::Matrix3d& rotation_projection,
                           const Eigen::Matrix3d& translation_projection,
                           double sigma)
      : initial_rotation_inverse_(initial_rotation.conjugate()),
        initial_translation_(initial_translation),
        rotation_projection_(rotation_projection),
        translation_projection_(translation_projection),
        inverse_sigma_(1.0 / sigma) {}

  static ceres::CostFunction* Create(const Eigen::Quaterniond& initial_rotation,
                                     const Eigen::Vector3d& initial_translation,
                                     const Eigen::Matrix3d& rotation_projection,
                                     const Eigen::Matrix3d& translation_projection,
                                     double sigma) {
    return new ceres::AutoDiffCostFunction<ExtrinsicHoldCostFunctor, 6, 4, 3>(
        new ExtrinsicHoldCostFunctor(initial_rotation,
                                     initial_translation,
                                     rotation_projection,
                                     translation_projection,
                                     sigma));
  }

  template <typename T>
  bool operator()(const T* const cam_from_lidar_rotation,
                  const T* const cam_from_lidar_translation,
                  T* residuals) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Quaternion<T> delta = colmap::EigenQuaternionMap<T>(cam_from_lidar_rotation) *
                                       initial_rotation_inverse_.cast<T>();
    const T delta_wxyz[4] = {delta.w(), delta.x(), delta.y(), delta.z()};
    Vector3 rotation_vector;
    ceres::QuaternionToAngleAxis(delta_wxyz, rotation_vector.data());
    const Vector3 translation_change =
        colmap::EigenVector3Map<T>(cam_from_lidar_translation) - initial_translation_.cast<T>();
    Eigen::Map<Vector3> rotation_residuals(residuals);
    Eigen::Map<Vector3> translation_residuals(residuals + 3);
    rotation_residuals = rotation_projection_.cast<T>() * rotation_vector * T(inverse_sigma_);
    translation_residuals =
        translation_projection_.cast<T>() * translation_change * T(inverse_sigma_);
    return true;
  }

 private:
  const Eigen::Quaterniond initial_rotation_inverse_;
  const Eigen::Vector3d initial_translation_;
  const Eigen::Matrix3d rotation_projection_;
  const Eigen::Matrix3d translation_projection_;
  const double inverse_sigma_;
};

}  // namespace colmap_lidar
