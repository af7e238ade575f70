#include "bridge/baselines/edge_axis_profile.h"

#include "colmap_ext/logging.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>

namespace colmap_lidar {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// The vertex of the parabola through (best - 1, best, best + 1) of `values` sampled every `step`
// from `first`; the best sample itself at either end.
double ParabolaPeak(const std::vector<double>& values, double first, double step) {
  const size_t best = std::max_element(values.begin(), values.end()) - values.begin();
  const double at_best = first + step * best;
  if (best == 0 || best + 1 == values.size()) return at_best;
  const double left = values[best - 1], centre = values[best], right = values[best + 1];
  const double curvature = left - 2 * centre + right;
  if (!(curvature < 0)) return at_best;
  return at_best + 0.5 * step * (left - right) / curvature;
}

}  // namespace

bool EdgeAxisProfileOptions::Check() const {
  CHECK_OPTION_GT(half_range_deg, 0);
  CHECK_OPTION_GT(step_deg, 0);
  CHECK_OPTION_LE(step_deg, half_range_deg);
  CHECK_OPTION_GE(num_bootstrap, 2);
  CHECK_OPTION_GT(min_depth_m, 0);
  return true;
}

colmap::Rigid3d TurnAboutCameraAxis(const colmap::Rigid3d& cam_from_lidar,
                                    const Eigen::Vector3d& axis_in_cam,
                                    double angle_deg) {
  colmap::Rigid3d turn;
  turn.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(angle_deg * kDegToRad, axis_in_cam.normalized()));
  return turn * cam_from_lidar;
}

EdgeAxisProfile ProfileEdgeObjective(const std::vector<EdgeStation>& stations,
                                     const colmap::Rigid3d& cam_from_lidar,
                                     const Eigen::Vector3d& axis_in_cam,
                                     const EdgeAxisProfileOptions& options) {
  THROW_CHECK(options.Check());
  THROW_CHECK(!stations.empty());
  THROW_CHECK_GT(axis_in_cam.norm(), 0);
  EdgeAxisProfile profile;
  profile.axis_in_cam = axis_in_cam.normalized();
  const int half = static_cast<int>(std::round(options.half_range_deg / options.step_deg));
  for (int k = -half; k <= half; ++k) profile.angles_deg.push_back(k * options.step_deg);
  const size_t num_angles = profile.angles_deg.size();
  // J per station (rows) and angle (columns).
  std::vector<std::vector<double>> per_station(stations.size(), std::vector<double>(num_angles));
#pragma omp parallel for schedule(dynamic, 4)
  for (int k = 0; k < static_cast<int>(num_angles); ++k) {
    const colmap::Rigid3d turned =
        TurnAboutCameraAxis(cam_from_lidar, profile.axis_in_cam, profile.angles_deg[k]);
    for (size_t s = 0; s < stations.size(); ++s) {
      per_station[s][k] = StationEdgeObjective(stations[s], turned, options.min_depth_m);
    }
  }
  auto sum_rows = [&](const std::vector<size_t>& rows) {
    std::vector<double> sum(num_angles, 0.0);
    for (const size_t s : rows) {
      for (size_t k = 0; k < num_angles; ++k) sum[k] += per_station[s][k];
    }
    return sum;
  };
  std::vector<size_t> all(stations.size());
  for (size_t s = 0; s < all.size(); ++s) all[s] = s;
  profile.objective = sum_rows(all);
  const double first = profile.angles_deg.front();
  profile.peak_deg = ParabolaPeak(profile.objective, first, options.step_deg);
  const size_t best = std::max_element(profile.objective.begin(), profile.objective.end()) -
                      profile.objective.begin();
  profile.at_range_end = best == 0 || best + 1 == num_angles;
  std::mt19937_64 random(options.seed);
  std::uniform_int_distribution<size_t> draw(0, stations.size() - 1);
  double sum = 0, sum_squares = 0;
  for (int b = 0; b < options.num_bootstrap; ++b) {
    std::vector<size_t> rows(stations.size());
    for (size_t& row : rows) row = draw(random);
    const double peak = ParabolaPeak(sum_rows(rows), first, options.step_deg);
    sum += peak;
    sum_squares += peak * peak;
  }
  // The bootstrap's plug-in variance is n / (n - 1) short for n stations (as a sample mean's).
  const double mean = sum / options.num_bootstrap;
  const double variance = std::max(
      0.0, (sum_squares - options.num_bootstrap * mean * mean) / (options.num_bootstrap - 1));
  const double n = static_cast<double>(stations.size());
  profile.sigma_deg = n > 1 ? std::sqrt(variance * n / (n - 1)) : 0.0;
  return profile;
}

}  // namespace colmap_lidar
