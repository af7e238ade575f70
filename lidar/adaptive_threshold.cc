#include "lidar/adaptive_threshold.h"

#include <cmath>
#include <stdexcept>

namespace colmap_lidar {

AdaptiveThreshold::AdaptiveThreshold(double initial_sigma_m,
                                     double min_motion_m,
                                     double max_range_m)
    : initial_sigma_m_(initial_sigma_m), min_motion_m_(min_motion_m), max_range_m_(max_range_m) {
  if (!(initial_sigma_m > 0) || !(min_motion_m >= 0) || !(max_range_m > 0)) {
    throw std::invalid_argument("AdaptiveThreshold: invalid sigma, motion or range");
  }
}

void AdaptiveThreshold::Update(const Eigen::Isometry3d& correction,
                               const Eigen::Isometry3d& motion) {
  if (motion.translation().norm() < min_motion_m_) return;
  // Eq. (4): the largest displacement of a point within max_range by the correction.
  const double theta = Eigen::AngleAxisd(correction.rotation()).angle();
  const double delta = 2.0 * max_range_m_ * std::sin(0.5 * theta) + correction.translation().norm();
  sum_squares_ += delta * delta;
  ++num_samples_;
}

double AdaptiveThreshold::Sigma() const {
  // Eq. (5)-(6).
  if (num_samples_ == 0) return initial_sigma_m_;
  return std::sqrt(sum_squares_ / num_samples_);
}

}  // namespace colmap_lidar
