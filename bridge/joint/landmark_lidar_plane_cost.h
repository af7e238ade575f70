// The landmark-to-LiDAR-plane residual E_m, a term Zhen et al. 2019 do not have but that fits their
// cost: it gives a monocular camera its depth and scale from the LiDAR. A landmark X seen in image i
// should lie on station i's LiDAR surface; with q and n (unit) the nearest planar sample of station i's
// cloud (lidar_i frame, re-associated every round like E_l):
//
//   E_m = n^T (lidar_i_from_world X - q) / sigma_m,   lidar_i_from_world = inverse(T_e) cam_i_from_world,
//
// so it constrains T_e = cam_from_lidar too. It is evaluated in camera i's frame, where it has the same
// value: E_m = (R_e n)^T (cam_i_from_world X - T_e q) / sigma_m.
//
// Keypoints on a surface seen at a grazing angle (a road ahead) are displaced systematically:
// across a keypoint's support the foreshortening changes, the more so the more oblique the view,
// so the landmark triangulated from several views sits off the surface along its normal
// (docs/benchmarks/landmark_offsets.md measures it at the true poses: on the road, not on the
// walls). With theta the angle between the ray and the normal, the offset is modelled as
// delta d sin(theta) tan(theta) (d the distance; delta a parameter, positive: towards the
// sensors), with X_c = cam_i_from_world X and m = R_e n:
//   E_m = (m^T (X_c - T_e q) - delta |m x X_c|^2 / sqrt((m^T X_c)^2 + kGrazing^2 |X_c|^2))
//         / sigma_m,
// zero head on; kGrazing caps tan(theta) at 1 / kGrazing for rays within 3 deg of the surface.
// A translation of cam_from_lidar shifts every residual of a surface alike; delta shifts them
// with distance and obliqueness, so landmarks at different distances and angles separate the two.
//
// Parameter blocks (COLMAP's): cam_i_from_world rotation [4] (Eigen quaternion, xyzw) and
// translation [3], the landmark's xyz [3] (world frame), cam_from_lidar rotation [4] and
// translation [3]; then delta [1].
#pragma once

#include "colmap/estimators/cost_functions.h"

#include <Eigen/Core>
#include <ceres/autodiff_cost_function.h>

namespace colmap_lidar {

class LandmarkLidarPlaneCostFunctor {
 public:
  LandmarkLidarPlaneCostFunctor(const Eigen::Vector3d& point_in_lidar_i,
                                const Eigen::Vector3d& normal_in_lidar_i,
                                double sigma)
      : point_in_lidar_i_(point_in_lidar_i),
        normal_in_lidar_i_(normal_in_lidar_i),
        inverse_sigma_(1.0 / sigma) {}

  static ceres::CostFunction* Create(const Eigen::Vector3d& point_in_lidar_i,
                                     const Eigen::Vector3d& normal_in_lidar_i,
                                     double sigma) {
    return new ceres::AutoDiffCostFunction<LandmarkLidarPlaneCostFunctor, 1, 4, 3, 3, 4, 3, 1>(
        new LandmarkLidarPlaneCostFunctor(point_in_lidar_i, normal_in_lidar_i, sigma));
  }

  template <typename T>
  bool operator()(const T* const cam_i_from_world_rotation,
                  const T* const cam_i_from_world_translation,
                  const T* const landmark_in_world,
                  const T* const cam_from_lidar_rotation,
                  const T* const cam_from_lidar_translation,
                  const T* const oblique_offset,
                  T* residual) const {
    residual[0] =
        Residual(cam_i_from_world_rotation,
                 cam_i_from_world_translation,
                 landmark_in_world,
                 cam_from_lidar_rotation,
                 Eigen::Matrix<T, 3, 1>(colmap::EigenVector3Map<T>(cam_from_lidar_translation)),
                 oblique_offset[0]);
    return true;
  }

  // E_m with station i's camera-from-LiDAR translation `cam_from_lidar_translation_i`.
  template <typename T>
  T Residual(const T* const cam_i_from_world_rotation,
             const T* const cam_i_from_world_translation,
             const T* const landmark_in_world,
             const T* const cam_from_lidar_rotation,
             const Eigen::Matrix<T, 3, 1>& cam_from_lidar_translation_i,
             const T& oblique_offset) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const auto cam_from_lidar_q = colmap::EigenQuaternionMap<T>(cam_from_lidar_rotation);
    const Vector3 landmark_in_cam_i = colmap::EigenQuaternionMap<T>(cam_i_from_world_rotation) *
                                          colmap::EigenVector3Map<T>(landmark_in_world) +
                                      colmap::EigenVector3Map<T>(cam_i_from_world_translation);
    const Vector3 target_in_cam_i =
        cam_from_lidar_q * point_in_lidar_i_.cast<T>() + cam_from_lidar_translation_i;
    const Vector3 normal_in_cam_i = cam_from_lidar_q * normal_in_lidar_i_.cast<T>();
    using std::sqrt;
    constexpr double kGrazing = 0.05;
    const T along = normal_in_cam_i.dot(landmark_in_cam_i);
    const T offset = oblique_offset * normal_in_cam_i.cross(landmark_in_cam_i).squaredNorm() /
                     sqrt(along * along + T(kGrazing * kGrazing) * landmark_in_cam_i.squaredNorm());
    return (normal_in_cam_i.dot(landmark_in_cam_i - target_in_cam_i) - offset) * T(inverse_sigma_);
  }

 private:
  const Eigen::Vector3d point_in_lidar_i_;
  const Eigen::Vector3d normal_in_lidar_i_;
  const double inverse_sigma_;
};

// E_m of a moving platform whose LiDAR clock is offset from the cameras' by dt (a parameter): station
// i's LiDAR pose is that of the camera at t_i + dt, so the LiDAR sample sits where the camera is dt
// later, t_e + dt v_i with v_i the camera's velocity in its own frame at station i:
//   E_m = (R_e n)^T (cam_i_from_world X - R_e q - t_e - dt v_i) / sigma_m.
// On a drive of constant velocity in the camera frame, dt and t_e along v are one direction (the
// covariance says so); turns and speed changes separate them.
// Parameter blocks: those of LandmarkLidarPlaneCostFunctor (delta last), then dt [1].
class TimedLandmarkLidarPlaneCostFunctor {
 public:
  TimedLandmarkLidarPlaneCostFunctor(const Eigen::Vector3d& point_in_lidar_i,
                                     const Eigen::Vector3d& normal_in_lidar_i,
                                     const Eigen::Vector3d& velocity_in_cam_i,
                                     double sigma)
      : plane_(point_in_lidar_i, normal_in_lidar_i, sigma), velocity_in_cam_i_(velocity_in_cam_i) {}

  static ceres::CostFunction* Create(const Eigen::Vector3d& point_in_lidar_i,
                                     const Eigen::Vector3d& normal_in_lidar_i,
                                     const Eigen::Vector3d& velocity_in_cam_i,
                                     double sigma) {
    return new ceres::
        AutoDiffCostFunction<TimedLandmarkLidarPlaneCostFunctor, 1, 4, 3, 3, 4, 3, 1, 1>(
            new TimedLandmarkLidarPlaneCostFunctor(
                point_in_lidar_i, normal_in_lidar_i, velocity_in_cam_i, sigma));
  }

  template <typename T>
  bool operator()(const T* const cam_i_from_world_rotation,
                  const T* const cam_i_from_world_translation,
                  const T* const landmark_in_world,
                  const T* const cam_from_lidar_rotation,
                  const T* const cam_from_lidar_translation,
                  const T* const oblique_offset,
                  const T* const time_offset,
                  T* residual) const {
    const Eigen::Matrix<T, 3, 1> translation_i =
        colmap::EigenVector3Map<T>(cam_from_lidar_translation) +
        time_offset[0] * velocity_in_cam_i_.cast<T>();
    residual[0] = plane_.Residual(cam_i_from_world_rotation,
                                  cam_i_from_world_translation,
                                  landmark_in_world,
                                  cam_from_lidar_rotation,
                                  translation_i,
                                  oblique_offset[0]);
    return true;
  }

 private:
  const LandmarkLidarPlaneCostFunctor plane_;
  const Eigen::Vector3d velocity_in_cam_i_;
};

// The prior on E_m's oblique-view offset delta: delta / sigma, with sigma from what is known of a
// keypoint's systematic offset (a fraction of a pixel) over the focal length.
class ObliqueOffsetPriorCostFunctor {
 public:
  explicit ObliqueOffsetPriorCostFunctor(double sigma) : inverse_sigma_(1.0 / sigma) {}

  static ceres::CostFunction* Create(double sigma) {
    return new ceres::AutoDiffCostFunction<ObliqueOffsetPriorCostFunctor, 1, 1>(
        new ObliqueOffsetPriorCostFunctor(sigma));
  }

  template <typename T>
  bool operator()(const T* const oblique_offset, T* residual) const {
    residual[0] = oblique_offset[0] * T(inverse_sigma_);
    return true;
  }

 private:
  const double inverse_sigma_;
};

}  // namespace colmap_lidar
