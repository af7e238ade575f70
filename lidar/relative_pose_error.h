// The residual of one pose-graph edge: a measured relative pose target_from_source against the
// estimated poses world_from_target and world_from_source (rotation as Eigen quaternion xyzw[4], then
// translation[3]). With the predicted T_pred = inverse(world_from_target) * world_from_source and the
// error E = T_pred * T_meas^-1 = (R_e, t_e):
//
//   r = W [2 vec(q_e); t_pred - R_e t_meas]
//
// which to first order is the increment [omega, t] in the target frame, whitened by the edge's square
// root information W (6x6; diagonal 1/sigma for independent rotation [rad] and translation [m] errors).
// Eigen only here; Create() (in the .cc) wraps it in a Ceres AutoDiffCostFunction<6, 4, 3, 4, 3>.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ceres {
class CostFunction;
}  // namespace ceres

namespace colmap_lidar {

class RelativePoseError {
 public:
  RelativePoseError(const Eigen::Isometry3d& target_from_source,
                    const Eigen::Matrix<double, 6, 6>& sqrt_information)
      : measured_rotation_(target_from_source.linear()),
        measured_translation_(target_from_source.translation()),
        sqrt_information_(sqrt_information) {}

  static ceres::CostFunction* Create(const Eigen::Isometry3d& target_from_source,
                                     const Eigen::Matrix<double, 6, 6>& sqrt_information);

  template <typename T>
  bool operator()(const T* world_from_target_q,
                  const T* world_from_target_t,
                  const T* world_from_source_q,
                  const T* world_from_source_t,
                  T* residuals) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_i(world_from_target_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_i(world_from_target_t);
    const Eigen::Map<const Eigen::Quaternion<T>> q_j(world_from_source_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_j(world_from_source_t);
    const Eigen::Quaternion<T> q_pred = q_i.conjugate() * q_j;
    const Eigen::Matrix<T, 3, 1> t_pred = q_i.conjugate() * (t_j - t_i);
    const Eigen::Quaternion<T> q_err = q_pred * measured_rotation_.cast<T>().conjugate();
    Eigen::Matrix<T, 6, 1> r;
    r.template head<3>() = T(2.0) * q_err.vec();
    r.template tail<3>() = t_pred - q_err * measured_translation_.cast<T>();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residuals);
    whitened = sqrt_information_.cast<T>() * r;
    return true;
  }

 private:
  Eigen::Quaterniond measured_rotation_;
  Eigen::Vector3d measured_translation_;
  Eigen::Matrix<double, 6, 6> sqrt_information_;
};

}  // namespace colmap_lidar
