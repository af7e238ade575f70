// The adaptive correspondence threshold of LiDAR odometry (Vizzo et al., "KISS-ICP", RA-L 2023,
// Sec. III-C, Eq. (4)-(6)): the constant-velocity prediction's error is a measure of how far apart
// correspondences can be. For a correction dT = T_pred^-1 T_icp with rotation angle theta and
// translation t, the largest displacement it causes within range r_max is bounded by
//   delta = 2 r_max sin(theta / 2) + |t|,
// and the threshold is tau = 3 sigma with sigma^2 the mean of delta^2 over the frames whose motion
// exceeded `min_motion_m` (standing still says nothing about the prediction); before any such frame,
// `initial_sigma_m` (tau = 3 initial_sigma_m).
#pragma once

#include <Eigen/Geometry>

namespace colmap_lidar {

class AdaptiveThreshold {
 public:
  // Throws std::invalid_argument for a non-positive sigma or range, a negative motion.
  AdaptiveThreshold(double initial_sigma_m, double min_motion_m, double max_range_m);

  // Records a frame: its correction dT and its motion relative to the previous frame.
  void Update(const Eigen::Isometry3d& correction, const Eigen::Isometry3d& motion);

  // sigma (the Geman-McClure scale of the ICP is sigma / 3) and tau = 3 sigma.
  double Sigma() const;
  double Threshold() const { return 3.0 * Sigma(); }

 private:
  double initial_sigma_m_;
  double min_motion_m_;
  double max_range_m_;
  double sum_squares_ = 0;
  int num_samples_ = 0;
};

}  // namespace colmap_lidar
