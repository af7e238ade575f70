#include "lidar/sweep_deskew.h"

#include "lidar/util/check_option.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

namespace {

// The motion per frame from sweep i to sweep j, or false when they are not comparable.
bool MotionPerFrame(const std::vector<Eigen::Isometry3d>& world_from_lidar,
                    const std::vector<double>& frame,
                    const std::vector<int>& component,
                    size_t i,
                    size_t j,
                    Eigen::Isometry3d* motion) {
  if (j >= world_from_lidar.size() || component[i] != component[j] || frame[i] == frame[j]) {
    return false;
  }
  const Eigen::Isometry3d i_from_j = world_from_lidar[i].inverse() * world_from_lidar[j];
  const double per_frame = 1.0 / std::abs(frame[j] - frame[i]);
  const Eigen::AngleAxisd rotation(i_from_j.rotation());
  motion->setIdentity();
  motion->linear() =
      Eigen::AngleAxisd(per_frame * rotation.angle(), rotation.axis()).toRotationMatrix();
  motion->translation() = per_frame * i_from_j.translation();
  return true;
}

}  // namespace

std::vector<SweepMotion> SweepMotionsFromPoses(
    const std::vector<Eigen::Isometry3d>& world_from_lidar,
    const std::vector<double>& frame,
    const std::vector<int>& component) {
  if (frame.size() != world_from_lidar.size() || component.size() != world_from_lidar.size()) {
    throw std::invalid_argument(
        "SweepMotionsFromPoses: poses, frames and components differ in size");
  }
  std::vector<SweepMotion> motions(world_from_lidar.size());
  for (size_t i = 0; i < motions.size(); ++i) {
    Eigen::Isometry3d next, previous;
    const bool has_next = MotionPerFrame(world_from_lidar, frame, component, i, i + 1, &next);
    const bool has_previous =
        i > 0 && MotionPerFrame(world_from_lidar, frame, component, i, i - 1, &previous);
    if (has_next) motions[i].mid_from_next_mid = next;
    if (has_previous) motions[i].mid_from_previous_mid = previous;
    if (has_next && !has_previous) motions[i].mid_from_previous_mid = next.inverse();
    if (has_previous && !has_next) motions[i].mid_from_next_mid = previous.inverse();
  }
  return motions;
}

std::vector<double> SweepClockFromTimes(const std::vector<std::pair<double, double>>& start_end) {
  std::vector<double> durations;
  for (const auto& [start, end] : start_end) {
    if (!(end > start)) throw std::invalid_argument("a sweep that does not end after it starts");
    durations.push_back(end - start);
  }
  std::vector<double> clock;
  if (durations.empty()) return clock;
  std::nth_element(durations.begin(), durations.begin() + durations.size() / 2, durations.end());
  const double period = durations[durations.size() / 2];
  const double origin = 0.5 * (start_end.front().first + start_end.front().second);
  for (const auto& [start, end] : start_end)
    clock.push_back((0.5 * (start + end) - origin) / period);
  return clock;
}

std::vector<double> SweepFractions(const PointCloud& sweep, const SweepTimingOptions& options) {
  ThrowUnlessValid(options, "SweepTimingOptions");
  std::vector<double> fractions(sweep.Size());
  if (!sweep.HasTimes()) {
    for (size_t i = 0; i < sweep.Size(); ++i)
      fractions[i] = SweepFraction(sweep.points[i], options);
    return fractions;
  }
  if (sweep.times.size() != sweep.Size()) {
    throw std::invalid_argument("a per-point time for each point is needed");
  }
  std::vector<double> sorted = sweep.times;
  std::sort(sorted.begin(), sorted.end());
  const double earliest = sorted.front(), span = sorted.back() - sorted.front();
  if (!(span > 0)) {
    throw std::invalid_argument(
        "the per-point times are all equal: they do not time the sweep (remove the time field to "
        "time the points by their azimuth)");
  }
  const double middle_span = sorted[sorted.size() * 99 / 100] - sorted[sorted.size() / 100];
  if (middle_span < 0.9 * 0.98 * span) {
    throw std::invalid_argument("per-point times out of range: 98 % of the points span " +
                                std::to_string(middle_span) + ", all of them " +
                                std::to_string(span) + " (a few times far from the sweep's)");
  }
  for (size_t i = 0; i < sweep.Size(); ++i) fractions[i] = (sweep.times[i] - earliest) / span;
  return fractions;
}

PointCloud DeskewSweep(const PointCloud& sweep,
                       const SweepMotion& motion,
                       const SweepTimingOptions& options) {
  const std::vector<double> fractions = SweepFractions(sweep, options);
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
    const double s = fractions[i] - 0.5;
    const int half = s >= 0 ? 1 : 0;
    const double a = std::abs(s);
    deskewed.points[i] =
        Eigen::AngleAxisd(a * rotations[half].angle(), rotations[half].axis()) * point +
        a * translations[half];
  }
  return deskewed;
}

}  // namespace colmap_lidar
