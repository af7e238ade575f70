// A weak prior on the translation of cam_from_lidar: E_p = (t - t_0) / sigma (3 residuals).
//
// Not part of the cost of Zhen et al. 2019. With degenerate motion (rotation about one axis, or none) a direction of
// T_e's translation is unobservable and Levenberg-Marquardt would wander along it (metres, in practice);
// with sigma of the order of a metre the prior holds that direction at the initial value while its
// information (1/sigma^2 = 1e-6 per mm^2) is negligible next to what the LiDAR gives an observable one.
#pragma once

#include <Eigen/Core>
#include <ceres/autodiff_cost_function.h>

namespace colmap_lidar {

class ExtrinsicTranslationPriorCostFunctor {
 public:
  ExtrinsicTranslationPriorCostFunctor(const Eigen::Vector3d& translation, double sigma)
      : translation_(translation), inverse_sigma_(1.0 / sigma) {}

  static ceres::CostFunction* Create(const Eigen::Vector3d& translation, double sigma) {
    return new ceres::AutoDiffCostFunction<ExtrinsicTranslationPriorCostFunctor, 3, 3>(
        new ExtrinsicTranslationPriorCostFunctor(translation, sigma));
  }

  template <typename T>
  bool operator()(const T* const cam_from_lidar_translation, T* residuals) const {
    for (int i = 0; i < 3; ++i) {
      residuals[i] = (cam_from_lidar_translation[i] - T(translation_[i])) * T(inverse_sigma_);
    }
    return true;
  }

 private:
  const Eigen::Vector3d translation_;
  const double inverse_sigma_;
};

}  // namespace colmap_lidar
