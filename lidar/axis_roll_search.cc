#include "lidar/axis_roll_search.h"

#include "lidar/util/check_option.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// Every station's points thinned by an even stride to at most `max_per_station`, with their station.
struct SampledPoints {
  std::vector<Eigen::Vector3d> point_in_cam;
  std::vector<size_t> station;
};

SampledPoints Sample(const std::vector<CameraDepthPoints>& points, int max_per_station) {
  SampledPoints sampled;
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t n = points[i].point_in_cam.size();
    const size_t stride = std::max<size_t>(1, (n + max_per_station - 1) / max_per_station);
    for (size_t k = 0; k < n; k += stride) {
      sampled.point_in_cam.push_back(points[i].point_in_cam[k]);
      sampled.station.push_back(i);
    }
  }
  return sampled;
}

// Mean truncated squared distance of the points moved by lidar_from_cam to their station's cloud.
double Score(const SampledPoints& sampled,
             const std::vector<const StationCloud*>& clouds,
             const Eigen::Isometry3d& lidar_from_cam,
             double truncation_m) {
  const double cap = truncation_m * truncation_m;
  double sum = 0;
  for (size_t k = 0; k < sampled.point_in_cam.size(); ++k) {
    size_t index = 0;
    double squared = cap;
    clouds[sampled.station[k]]->tree->Nearest(
        lidar_from_cam * sampled.point_in_cam[k], &index, &squared);
    sum += std::min(squared, cap);
  }
  return sum / sampled.point_in_cam.size();
}

// Index of the lowest local minimum (cyclic) at least `min_separation` candidates away from `best`;
// `best` if there is none.
size_t RunnerUp(const std::vector<double>& scores, size_t best, size_t min_separation) {
  const size_t n = scores.size();
  size_t runner_up = best;
  for (size_t k = 0; k < n; ++k) {
    const size_t gap = k > best ? k - best : best - k;
    const bool local_minimum =
        scores[k] <= scores[(k + n - 1) % n] && scores[k] <= scores[(k + 1) % n];
    if (!local_minimum || std::min(gap, n - gap) < min_separation) continue;
    if (runner_up == best || scores[k] < scores[runner_up]) runner_up = k;
  }
  return runner_up;
}

void CheckInput(const std::vector<CameraDepthPoints>& points,
                const std::vector<const StationCloud*>& clouds,
                const Eigen::Vector3d& axis_in_cam,
                const AxisRollSearchOptions& options) {
  ThrowUnlessValid(options, "AxisRollSearchOptions");
  if (points.size() != clouds.size()) {
    throw std::invalid_argument("SearchRollAboutAxis: one cloud per station's points needed");
  }
  if (!(axis_in_cam.norm() > 0)) {
    throw std::invalid_argument("SearchRollAboutAxis: the axis is zero");
  }
  for (const StationCloud* cloud : clouds) {
    if (cloud == nullptr || !cloud->tree || cloud->tree->Size() == 0) {
      throw std::invalid_argument("SearchRollAboutAxis: a station cloud without points or tree");
    }
  }
}

}  // namespace

bool AxisRollSearchOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(step_deg, 0);
  LIDAR_CHECK_OPTION_LE(step_deg, 90);
  LIDAR_CHECK_OPTION_GE(max_points_per_station, 1);
  LIDAR_CHECK_OPTION_GT(truncation_m, 0);
  LIDAR_CHECK_OPTION_GE(min_separation_deg, 0);
  return true;
}

AxisRollSearchResult SearchRollAboutAxis(const std::vector<CameraDepthPoints>& points,
                                         const std::vector<const StationCloud*>& clouds,
                                         const Eigen::Isometry3d& start_cam_from_lidar,
                                         const Eigen::Vector3d& axis_in_cam,
                                         const AxisRollSearchOptions& options) {
  CheckInput(points, clouds, axis_in_cam, options);
  const SampledPoints sampled = Sample(points, options.max_points_per_station);
  if (sampled.point_in_cam.empty()) {
    throw std::invalid_argument("SearchRollAboutAxis: no camera points");
  }
  const Eigen::Vector3d axis = axis_in_cam.normalized();
  const size_t num_rolls = static_cast<size_t>(std::ceil(360.0 / options.step_deg));
  const auto at_roll = [&](size_t k) {
    Eigen::Isometry3d cam_from_lidar = start_cam_from_lidar;
    cam_from_lidar.linear() =
        Eigen::AngleAxisd(k * options.step_deg * kDegToRad, axis).toRotationMatrix() *
        start_cam_from_lidar.linear();
    return cam_from_lidar;
  };
  std::vector<double> scores(num_rolls);
  for (size_t k = 0; k < num_rolls; ++k) {
    scores[k] = Score(sampled, clouds, at_roll(k).inverse(), options.truncation_m);
  }
  const size_t best = std::min_element(scores.begin(), scores.end()) - scores.begin();
  const size_t runner_up = RunnerUp(
      scores, best, static_cast<size_t>(std::ceil(options.min_separation_deg / options.step_deg)));
  AxisRollSearchResult result;
  result.cam_from_lidar = at_roll(best);
  result.best_roll_deg = best * options.step_deg;
  result.best_rms_m = std::sqrt(scores[best]);
  result.runner_up_roll_deg = runner_up * options.step_deg;
  result.runner_up_rms_m = std::sqrt(scores[runner_up]);
  result.num_points = sampled.point_in_cam.size();
  for (double score : scores) result.rms_by_roll.push_back(std::sqrt(score));
  return result;
}

}  // namespace colmap_lidar
