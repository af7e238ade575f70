// The depth-prior residual E_d of the joint cost of Zhen et al. 2019, in COLMAP 3.10's parameter layout:
//
//   E_d = (depth(X_cam) - d) / sigma_d,   X_cam = R(q_cam_from_world) X_world + t_cam_from_world
//
// with the cam_from_world rotation as an Eigen quaternion (xyzw storage, COLMAP's
// Rigid3d::rotation.coeffs()), the translation and the landmark X_world (COLMAP's Point3D::xyz).
//
// depth(X_cam) is the z coordinate by default. Zhen et al. 2019 write the range ||X_cam||, but a rectified
// stereo pair measures disparity, i.e. z (Z = b f / d), and our depth maps store z in the original left
// camera; comparing z with z keeps the residual unbiased off the optical axis, where range exceeds z by
// up to 1/cos(24 deg) = 9 % at the image corner of a 48 deg lens. DepthType::kRange is there for priors
// that really are ranges (e.g. time-of-flight sensors).
//
// Beyond the paper, d is corrected by the stereo rig's systematic disparity error, a field over the
// left image in inverse depth (1/m; times b f it is disparity in pixels):
//
//   1/d_corrected = 1/d + c0 + c1 x + c2 y,   (x, y) the keypoint's normalised image coordinates.
//
// Residual rectification errors give these three terms: a relative yaw of the two cameras (or a
// principal point offset) a constant disparity offset, a focal length mismatch one that grows with
// x, a relative roll one that grows with y. An error common to every prior cannot show in their
// scatter. The joint adjuster estimates c against the LiDAR's depth (E_m) when asked to
// (JointAdjusterOptions::estimate_depth_bias); otherwise c is held at zero and the covariance of
// cam_from_lidar considers it (ObservabilityOptions::disparity_bias_sigma_px).
#pragma once

#include "colmap/estimators/cost_functions.h"
#include "colmap/geometry/rigid3.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/ceres.h>

namespace colmap_lidar {

enum class DepthType { kZ, kRange };

template <typename T>
T DepthOfPoint(const Eigen::Matrix<T, 3, 1>& point_in_cam, DepthType type) {
  if (type == DepthType::kZ) return point_in_cam.z();
  return point_in_cam.norm();
}

// One depth prior: the measured depth d, its sigma_d and the keypoint's normalised image coordinates.
struct DepthPriorMeasurement {
  double depth = 0;
  double sigma = 1;
  Eigen::Vector2d normalized_xy = Eigen::Vector2d::Zero();
};

// d_corrected of the header comment for the bias field c = bias[0..2].
template <typename T>
T CorrectedDepth(const DepthPriorMeasurement& measurement, const T* const bias) {
  return T(1) / (T(1.0 / measurement.depth) + bias[0] + bias[1] * measurement.normalized_xy.x() +
                 bias[2] * measurement.normalized_xy.y());
}

// Pose, landmark and bias field are parameter blocks: cam_from_world rotation [4], translation [3],
// point [3], bias [3].
class DepthPriorCostFunctor {
 public:
  DepthPriorCostFunctor(const DepthPriorMeasurement& measurement, DepthType type)
      : measurement_(measurement), inverse_sigma_(1.0 / measurement.sigma), type_(type) {}

  static ceres::CostFunction* Create(const DepthPriorMeasurement& measurement,
                                     DepthType type = DepthType::kZ) {
    return new ceres::AutoDiffCostFunction<DepthPriorCostFunctor, 1, 4, 3, 3, 3>(
        new DepthPriorCostFunctor(measurement, type));
  }

  template <typename T>
  bool operator()(const T* const cam_from_world_rotation,
                  const T* const cam_from_world_translation,
                  const T* const point_in_world,
                  const T* const bias,
                  T* residual) const {
    const Eigen::Matrix<T, 3, 1> point_in_cam =
        colmap::EigenQuaternionMap<T>(cam_from_world_rotation) *
            colmap::EigenVector3Map<T>(point_in_world) +
        colmap::EigenVector3Map<T>(cam_from_world_translation);
    residual[0] = (DepthOfPoint(point_in_cam, type_) - CorrectedDepth(measurement_, bias)) *
                  T(inverse_sigma_);
    return true;
  }

 private:
  const DepthPriorMeasurement measurement_;
  const double inverse_sigma_;
  const DepthType type_;
};

// The same residual for an image whose pose COLMAP holds constant (its pose is not a parameter block in
// COLMAP's problem, as for ReprojErrorConstantPoseCostFunction): the landmark [3] and the bias field
// [3] are the parameters.
class DepthPriorConstantPoseCostFunctor {
 public:
  DepthPriorConstantPoseCostFunctor(const colmap::Rigid3d& cam_from_world,
                                    const DepthPriorMeasurement& measurement,
                                    DepthType type)
      : cam_from_world_(cam_from_world),
        measurement_(measurement),
        inverse_sigma_(1.0 / measurement.sigma),
        type_(type) {}

  static ceres::CostFunction* Create(const colmap::Rigid3d& cam_from_world,
                                     const DepthPriorMeasurement& measurement,
                                     DepthType type = DepthType::kZ) {
    return new ceres::AutoDiffCostFunction<DepthPriorConstantPoseCostFunctor, 1, 3, 3>(
        new DepthPriorConstantPoseCostFunctor(cam_from_world, measurement, type));
  }

  template <typename T>
  bool operator()(const T* const point_in_world, const T* const bias, T* residual) const {
    const Eigen::Matrix<T, 3, 1> point_in_cam =
        cam_from_world_.rotation.cast<T>() * colmap::EigenVector3Map<T>(point_in_world) +
        cam_from_world_.translation.cast<T>();
    residual[0] = (DepthOfPoint(point_in_cam, type_) - CorrectedDepth(measurement_, bias)) *
                  T(inverse_sigma_);
    return true;
  }

 private:
  const colmap::Rigid3d cam_from_world_;
  const DepthPriorMeasurement measurement_;
  const double inverse_sigma_;
  const DepthType type_;
};

}  // namespace colmap_lidar
