#include "lidar/sweep_deskew.h"

#include "lidar/check_option.h"

#include <cmath>

namespace colmap_lidar {

bool SweepTimingOptions::Check() const {
  LIDAR_CHECK_OPTION(std::isfinite(start_azimuth_deg));
  return true;
}

double SweepFraction(const Eigen::Vector3d& point_in_lidar, const SweepTimingOptions& options) {
  const double azimuth = std::atan2(point_in_lidar.y(), point_in_lidar.x());
  double turned = azimuth - options.start_azimuth_deg * M_PI / 180;
  if (!options.counter_clockwise) turned = -turned;
  const double fraction = std::fmod(turned, 2 * M_PI) / (2 * M_PI);
  return fraction < 0 ? fraction + 1 : fraction;
}

PointCloud DeskewSweep(const PointCloud& sweep,
                       const SweepMotion& motion,
                       const SweepTimingOptions& options) {
  ThrowUnlessValid(options, "SweepTimingOptions");
  // Index 0: towards the previous middle (s < 0), 1: towards the next one.
  const Eigen::AngleAxisd rotations[2] = {
      Eigen::AngleAxisd(motion.mid_from_previous_mid.rotation()),
      Eigen::AngleAxisd(motion.mid_from_next_mid.rotation())};
  const Eigen::Vector3d translations[2] = {motion.mid_from_previous_mid.translation(),
                                           motion.mid_from_next_mid.translation()};
  PointCloud deskewed;
  deskewed.points.resize(sweep.Size());
  deskewed.colors = sweep.colors;
  deskewed.intensities = sweep.intensities;
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < static_cast<int64_t>(sweep.Size()); ++i) {
    const Eigen::Vector3d& point = sweep.points[i];
    const double s = SweepFraction(point, options) - 0.5;
    const int half = s >= 0 ? 1 : 0;
    const double a = std::abs(s);
    deskewed.points[i] =
        Eigen::AngleAxisd(a * rotations[half].angle(), rotations[half].axis()) * point +
        a * translations[half];
  }
  return deskewed;
}

}  // namespace colmap_lidar
