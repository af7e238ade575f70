// Observability of the camera-LiDAR extrinsic T_e = cam_from_lidar after the joint solve:
// - its 6x6 covariance, marginalised from the joint problem's Gauss-Newton information (J^T J with
//   every other variable block eliminated by a Schur complement), scaled by the a-posteriori variance
//   factor, with its eigen-decomposition; directions whose standard deviation exceeds a threshold are
//   named in words;
// - the seed's uniqueness test on the relative motions: T_e is unique only with >= 3 stations whose
//   relative rotation axes are not all parallel (hand-eye calibration, AX = XB).
// Units: rotation as a rotation vector about the camera axes in degrees (Ceres' EigenQuaternionManifold
// tangent, left-multiplied), translation in millimetres along the camera axes.
#pragma once

#include "colmap/scene/reconstruction.h"

#include <Eigen/Core>
#include <ceres/problem.h>

#include <array>
#include <string>
#include <vector>

namespace colmap_lidar {

struct ObservabilityOptions {
  // A direction of T_e whose standard deviation exceeds these is called unobservable.
  double unobservable_translation_mm = 5.0;
  double unobservable_rotation_deg = 0.2;
  double min_rotation_deg =
      2.0;  // relative rotations below this do not count as rotating
  double max_parallel_axes_deg = 5.0;  // axes closer than this are parallel

  bool Check() const;
};

struct ExtrinsicUncertainty {
  bool computed = false;
  std::string message;  // why not, if not computed
  // 6x6 covariance of (rotation vector [deg] about the camera axes, translation [mm]) of cam_from_lidar,
  // scaled by the a-posteriori variance factor (see variance_factor).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  double variance_factor = 1;  // 2 cost / (residuals - parameters)
  Eigen::Matrix<double, 6, 1> eigenvalues =
      Eigen::Matrix<double, 6, 1>::Zero();  // std devs, ascending
  Eigen::Matrix<double, 6, 6> eigenvectors =
      Eigen::Matrix<double, 6, 6>::Zero();  // columns
  std::vector<std::string>
      unobservable;  // one sentence per unobservable direction
};

struct MotionAnalysis {
  int num_stations = 0;
  int num_rotating_pairs = 0;  // relative rotation above 2 deg
  double max_axis_angle_deg =
      0;  // largest angle between two relative rotation axes
  Eigen::Vector3d common_axis_in_cam =
      Eigen::Vector3d::Zero();  // if all axes are parallel
  bool unique = false;  // the seed's test: >= 3 stations, axes not all parallel
  std::string verdict;
};

// The seed's uniqueness test on the relative motions of the registered cameras.
MotionAnalysis AnalyseMotion(const colmap::Reconstruction& reconstruction,
                             const ObservabilityOptions& options);

// Marginal covariance of T_e's blocks in `problem` (both must be variable parameter blocks; the rotation
// with a quaternion manifold of tangent size 3, the translation possibly with a subset manifold).
// `motion` turns unobservable directions into advice.
// `held_translation`: translation components held constant by a subset manifold (known exactly).
ExtrinsicUncertainty ComputeExtrinsicUncertainty(
    ceres::Problem* problem,
    double* cam_from_lidar_rotation,
    double* cam_from_lidar_translation,
    const std::array<bool, 3>& held_translation,
    const MotionAnalysis& motion,
    const ObservabilityOptions& options);

}  // namespace colmap_lidar
