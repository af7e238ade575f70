// LiDAR odometry for the sweeps of a moving platform (Vizzo et al., "KISS-ICP: In Defense of
// Point-to-Point ICP", RA-L 2023): frame by frame,
//   1. constant-velocity prediction: T_pred = T_{k-1} Exp(v dt), v the last motion per sweep;
//   2. de-skewing of the sweep by that velocity (lidar/sweep_deskew.h; per-point times from the
//      sweep model's azimuth), unless the scans are already motion-compensated;
//   3. subsampling: one point per voxel of alpha v for the map, of beta v for the registration
//      (alpha = 0.5, beta = 1.5; v = voxel size);
//   4. robust ICP against the local voxel-hash map (lidar/frame_to_map_icp.h: point-to-plane where
//      the map is locally a plane, point-to-point where it is scattered) with the adaptive
//      threshold (lidar/adaptive_threshold.h);
//   5. the map updated with the registered frame, far voxels dropped.
// The first motion has no velocity to predict it: the second frame starts from rest with the
// initial threshold (tau = 3 initial_sigma_m) and graduated non-convexity (Black & Rangarajan,
// IJCV 1996; Yang et al., RA-L 2020): its ICP runs with the kernel's scale at 3 sigma, then sigma,
// then the sigma / 3 of every frame, each from the last. With only the narrow kernel, the points
// that show a platform already moving at driving speed (poles, the ends of parked cars) sit in the
// kernel's tail, and along a street whose facades hold the travel weakly the ICP stops near rest.
// Every frame gets a pose. Its information is measured point-to-plane against the map; a frame
// whose weakest constrained direction is below `degenerate_ratio` of its strongest (a tunnel, a
// street of bare facades) is flagged with that direction, never silently accepted.
#pragma once

#include "lidar/adaptive_threshold.h"
#include "lidar/frame_to_map_icp.h"
#include "lidar/registration_quality.h"
#include "lidar/sweep_deskew.h"
#include "lidar/voxel_hash_map.h"

#include <Eigen/Geometry>

#include <optional>
#include <vector>

namespace colmap_lidar {

struct LidarOdometryOptions {
  double max_range_m = 100.0;
  // Returns nearer than this are the platform itself.
  double min_range_m = 2.0;
  // Edge of the map's voxels; 0: max_range_m / 100 (KISS-ICP).
  double voxel_size_m = 0;
  int max_points_per_voxel = 20;
  // The adaptive threshold before the first moving frame, and the motion that counts as moving.
  double initial_sigma_m = 2.0;
  double min_motion_m = 0.1;
  // Sweeps taken while moving are de-skewed with the predicted motion; off for scans that are
  // already motion-compensated.
  bool deskew = true;
  SweepTimingOptions timing;
  FrameToMapIcpOptions icp;
  // Weakest over strongest eigenvalue of the translation's information (the Schur complement of the
  // rotation in the point-to-plane information) below which the frame is degenerate.
  double degenerate_ratio = 0.02;

  double VoxelSize() const { return voxel_size_m > 0 ? voxel_size_m : max_range_m / 100.0; }
  bool Check() const;
};

struct OdometryFrame {
  Eigen::Isometry3d world_from_lidar = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d prediction = Eigen::Isometry3d::Identity();
  // [omega, t] of a right increment in the LiDAR frame: plane_rms^2 H^-1; absent for the first
  // frame (the world's origin) and for a degenerate frame (a direction without information).
  std::optional<Eigen::Matrix<double, 6, 6>> covariance;
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  ConstraintAnalysis constraints;
  bool degenerate = false;
  bool converged = false;
  int num_iterations = 0;
  size_t num_points = 0;  // after the range filter
  size_t num_source_points = 0;
  size_t num_correspondences = 0;
  double threshold_m = 0;  // tau of this frame's ICP
  double rms_m = 0;
  double plane_rms_m = 0;
};

class LidarOdometry {
 public:
  // Throws std::invalid_argument for invalid options.
  explicit LidarOdometry(const LidarOdometryOptions& options);

  // Registers the next frame: its sweep in its LiDAR frame (with per-point times, if it has them,
  // for the de-skewing), taken at `clock` (the sweep's middle, in sweep durations; increasing).
  // Throws std::invalid_argument for a clock that does not increase or per-point times that do not
  // time a sweep (lidar/sweep_deskew.h SweepFractions), std::runtime_error for a frame with no
  // point in range.
  const OdometryFrame& RegisterFrame(const PointCloud& sweep, double clock);
  const OdometryFrame& RegisterFrame(const std::vector<Eigen::Vector3d>& points, double clock);

  const std::vector<OdometryFrame>& Frames() const { return frames_; }

 private:
  std::vector<Eigen::Vector3d> Preprocess(const PointCloud& sweep) const;
  void FinishFrame(const FrameToMapIcpResult& icp, OdometryFrame* frame) const;

  LidarOdometryOptions options_;
  VoxelHashMap map_;
  AdaptiveThreshold threshold_;
  std::vector<OdometryFrame> frames_;
  double last_clock_ = 0;
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();
};

// The motion `motion` scaled to `fraction` of itself (rotation angle and translation), constant
// velocity's interpolation and extrapolation.
Eigen::Isometry3d ScaleMotion(const Eigen::Isometry3d& motion, double fraction);

}  // namespace colmap_lidar
