// A Gaussian on cam_from_lidar about a reference (R_0, t_0), whitened by a 6x6 matrix W:
//
//   E_x = W [rotvec(R R_0^-1); t - t_0]    (6 residuals; rotation [rad] about the camera axes)
//
// In the joint problem (not in the cost of Zhen et al. 2019) it is outside knowledge of T_e: rig.json's
// guess with its sigmas, or a fit to data no other term sees (the vertical alignment of image line
// segments), W = the square root of its information (the inverse of its covariance).
// Parameter blocks (COLMAP's layout): cam_from_lidar rotation [4] (Eigen quaternion, xyzw in memory)
// and translation [3].
#pragma once

#include "colmap/estimators/cost_functions.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

namespace colmap_lidar {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

class ExtrinsicDeviationCostFunctor {
 public:
  ExtrinsicDeviationCostFunctor(const Eigen::Quaterniond& reference_rotation,
                                const Eigen::Vector3d& reference_translation,
                                const Matrix6d& whitening)
      : reference_rotation_inverse_(reference_rotation.conjugate()),
        reference_translation_(reference_translation),
        whitening_(whitening) {}

  static ceres::CostFunction* Create(const Eigen::Quaterniond& reference_rotation,
                                     const Eigen::Vector3d& reference_translation,
                                     const Matrix6d& whitening) {
    return new ceres::AutoDiffCostFunction<ExtrinsicDeviationCostFunctor, 6, 4, 3>(
        new ExtrinsicDeviationCostFunctor(reference_rotation, reference_translation, whitening));
  }

  template <typename T>
  bool operator()(const T* const cam_from_lidar_rotation,
                  const T* const cam_from_lidar_translation,
                  T* residuals) const {
    const Eigen::Quaternion<T> delta = colmap::EigenQuaternionMap<T>(cam_from_lidar_rotation) *
                                       reference_rotation_inverse_.cast<T>();
    const T delta_wxyz[4] = {delta.w(), delta.x(), delta.y(), delta.z()};
    Eigen::Matrix<T, 6, 1> deviation;
    ceres::QuaternionToAngleAxis(delta_wxyz, deviation.data());
    deviation.template tail<3>() =
        colmap::EigenVector3Map<T>(cam_from_lidar_translation) - reference_translation_.cast<T>();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residuals);
    whitened = whitening_.cast<T>() * deviation;
    return true;
  }

 private:
  const Eigen::Quaterniond reference_rotation_inverse_;
  const Eigen::Vector3d reference_translation_;
  const Matrix6d whitening_;
};

// W of a covariance (rotation [rad] about the camera axes, then translation [m]): W^T W = covariance^-1.
// Throws std::invalid_argument unless the covariance is symmetric positive definite.
Matrix6d WhiteningOfCovariance(const Matrix6d& covariance);

}  // namespace colmap_lidar
