// The LiDAR residual E_l of the joint cost of Zhen et al. 2019, in COLMAP 3.10's parameter layout. An observation pairs
// a point p of station j's cloud (lidar_j frame) with a point q and unit normal n of station i's cloud
// (lidar_i frame):
//
//   E_l = n^T (lidar_i_from_lidar_j p - q) / sigma_l,
//   lidar_i_from_lidar_j = inverse(T_e) * cam_i_from_world * inverse(cam_j_from_world) * T_e,
//
// with T_e = cam_from_lidar shared by all stations. It is evaluated in camera i's frame, where it has the
// same value (a rigid motion preserves the dot product): E_l = (R_e n)^T (p_cam_i - T_e q) / sigma_l with
// p_cam_i = cam_i_from_world * inverse(cam_j_from_world) * T_e * p.
//
// Parameter blocks (COLMAP's): cam_i_from_world rotation [4] (Eigen quaternion, xyzw) and translation [3],
// cam_j_from_world rotation [4] and translation [3], cam_from_lidar rotation [4] and translation [3].
#pragma once

#include "colmap/estimators/cost_functions.h"

#include <Eigen/Core>
#include <ceres/autodiff_cost_function.h>

namespace colmap_lidar {

class LidarPointToPlaneCostFunctor {
 public:
  LidarPointToPlaneCostFunctor(const Eigen::Vector3d& point_in_lidar_j,
                               const Eigen::Vector3d& point_in_lidar_i,
                               const Eigen::Vector3d& normal_in_lidar_i,
                               double sigma)
      : point_in_lidar_j_(point_in_lidar_j),
        point_in_lidar_i_(point_in_lidar_i),
        normal_in_lidar_i_(normal_in_lidar_i),
        inverse_sigma_(1.0 / sigma) {}

  static ceres::CostFunction* Create(const Eigen::Vector3d& point_in_lidar_j,
                                     const Eigen::Vector3d& point_in_lidar_i,
                                     const Eigen::Vector3d& normal_in_lidar_i,
                                     double sigma) {
    return new ceres::AutoDiffCostFunction<LidarPointToPlaneCostFunctor, 1, 4, 3, 4, 3, 4, 3>(
        new LidarPointToPlaneCostFunctor(
            point_in_lidar_j, point_in_lidar_i, normal_in_lidar_i, sigma));
  }

  template <typename T>
  bool operator()(const T* const cam_i_from_world_rotation,
                  const T* const cam_i_from_world_translation,
                  const T* const cam_j_from_world_rotation,
                  const T* const cam_j_from_world_translation,
                  const T* const cam_from_lidar_rotation,
                  const T* const cam_from_lidar_translation,
                  T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const auto cam_from_lidar_q = colmap::EigenQuaternionMap<T>(cam_from_lidar_rotation);
    const auto cam_from_lidar_t = colmap::EigenVector3Map<T>(cam_from_lidar_translation);
    // p: lidar_j -> cam_j -> world -> cam_i.
    const Vector3 point_in_cam_j =
        cam_from_lidar_q * point_in_lidar_j_.cast<T>() + cam_from_lidar_t;
    const Vector3 point_in_world =
        colmap::EigenQuaternionMap<T>(cam_j_from_world_rotation).conjugate() *
        (point_in_cam_j - colmap::EigenVector3Map<T>(cam_j_from_world_translation));
    const Vector3 point_in_cam_i =
        colmap::EigenQuaternionMap<T>(cam_i_from_world_rotation) * point_in_world +
        colmap::EigenVector3Map<T>(cam_i_from_world_translation);
    // q and n: lidar_i -> cam_i.
    const Vector3 target_in_cam_i =
        cam_from_lidar_q * point_in_lidar_i_.cast<T>() + cam_from_lidar_t;
    const Vector3 normal_in_cam_i = cam_from_lidar_q * normal_in_lidar_i_.cast<T>();
    residual[0] = normal_in_cam_i.dot(point_in_cam_i - target_in_cam_i) * T(inverse_sigma_);
    return true;
  }

 private:
  const Eigen::Vector3d point_in_lidar_j_;
  const Eigen::Vector3d point_in_lidar_i_;
  const Eigen::Vector3d normal_in_lidar_i_;
  const double inverse_sigma_;
};

}  // namespace colmap_lidar
