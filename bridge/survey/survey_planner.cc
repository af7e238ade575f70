#include "bridge/survey/survey_planner.h"

#include "bridge/simulation/sensor_pod.h"
#include "bridge/survey/surface_world.h"
#include "colmap_ext/logging.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace sim {
namespace {

constexpr const char* kAxisNames[3] = {"x", "y", "z"};

// The worst sigma / threshold over the six axes, and its name.
void FindWorstAxis(const ObservabilityOptions& thresholds, CalibrationPrediction* prediction) {
  prediction->worst_ratio = -1;
  for (int axis = 0; axis < 6; ++axis) {
    const bool rotation = axis < 3;
    const double ratio =
        rotation
            ? prediction->rotation_sigma_deg[axis] / thresholds.unobservable_rotation_deg
            : prediction->translation_sigma_mm[axis - 3] / thresholds.unobservable_translation_mm;
    if (ratio > prediction->worst_ratio) {
      prediction->worst_ratio = ratio;
      prediction->worst_axis =
          std::string(rotation ? "rotation about " : "translation along ") + kAxisNames[axis % 3];
    }
  }
}

// Where the plan's stations stand: their mean horizontal distance from the structure's centre.
double MeanStationDistance(const SurveyTarget& target,
                           const std::vector<colmap::Rigid3d>& stations) {
  double sum = 0;
  for (const colmap::Rigid3d& station : stations) {
    sum += (colmap::Inverse(station).translation - target.center).head<2>().norm();
  }
  return sum / stations.size();
}

std::string Describe(const char* kind, double azimuth_deg, double distance, const char* how) {
  std::ostringstream text;
  text.precision(3);
  text << kind << " station at azimuth " << azimuth_deg << " deg, " << distance
       << " m from the structure's centre" << how;
  return text.str();
}

}  // namespace

SurveyTarget TargetOfScene(const Scene& scene) {
  SurveyTarget target;
  target.world = WorldOfScene(scene);
  target.center = scene.ObjectCenter();
  target.height = scene.ObjectHeight();
  return target;
}

SurveyTarget TargetOfSurface(std::shared_ptr<const PointCloud> surface) {
  SurveyTarget target;
  if (surface->Empty()) throw std::invalid_argument("The surface has no points");
  Eigen::Vector3d low = surface->points[0], high = low;
  for (const Eigen::Vector3d& p : surface->points) {
    low = low.cwiseMin(p), high = high.cwiseMax(p);
  }
  target.world = WorldOfSurface(surface, low.z());
  target.center = 0.5 * (low + high);
  target.height = high.z() - low.z();
  target.ground_z = low.z();
  return target;
}

JointAdjusterOptions SurveyPlanOptions::DefaultAdjusterOptions() {
  // As in the coverage test that validates the reported sigmas at this noise.
  JointAdjusterOptions adjuster;
  adjuster.sigma_lidar_m = 0.01;
  adjuster.num_association_rounds = 2;
  adjuster.association.num_samples = 500;
  adjuster.hold_unobservable = false;
  adjuster.observability.cluster_grouping = ObservabilityOptions::ClusterGrouping::kLandmark;
  return adjuster;
}

bool SurveyPlanOptions::Check() const {
  CHECK_OPTION_GE(pixel_noise, 0);
  CHECK_OPTION_GE(depth_noise_sigmas, 0);
  CHECK_OPTION_GE(lidar_range_noise_m, 0);
  CHECK_OPTION_GE(lidar_points, 1000);
  CHECK_OPTION_GE(landmark_stride, 1);
  CHECK_OPTION_GE(num_candidate_positions, 0);
  CHECK_OPTION_GE(candidate_tilt_deg, 0);
  CHECK_OPTION_LT(candidate_tilt_deg, 45);
  CHECK_OPTION_GT(tilted_height_m, 0);
  return adjuster.Check();
}

CalibrationPrediction PredictCalibration(const SurveyTarget& target,
                                         const std::vector<colmap::Rigid3d>& stations,
                                         const SurveyPlanOptions& options) {
  THROW_CHECK(options.Check());
  if (stations.size() < 2) throw std::invalid_argument("A plan needs at least 2 stations");
  SyntheticJointOptions synthetic;
  synthetic.lidar_points = options.lidar_points;
  synthetic.lidar_range_noise_m = options.lidar_range_noise_m;
  synthetic.pixel_noise = options.pixel_noise;
  synthetic.depth_noise_sigmas = options.depth_noise_sigmas;
  synthetic.landmark_stride = options.landmark_stride;
  synthetic.noise_seed = options.seed;
  // A start near the truth: the prediction is of the uncertainty at convergence.
  synthetic.extrinsic_rotation_deg = 0.5;
  synthetic.extrinsic_translation_m = 0.01;
  auto problem = MakeSyntheticJointProblem(target.world, stations, synthetic);
  colmap::Rigid3d cam_from_lidar = problem->cam_from_lidar;
  const JointAdjustmentSummary summary =
      JointAdjuster(options.adjuster).Run(problem->data, &problem->reconstruction, &cam_from_lidar);
  CalibrationPrediction prediction;
  prediction.motion = summary.motion;
  prediction.uncertainty = summary.uncertainty;
  if (!summary.uncertainty.computed) {
    throw std::runtime_error("The plan's uncertainty could not be computed: " +
                             summary.uncertainty.message);
  }
  const Eigen::Matrix<double, 6, 1> sigma = summary.uncertainty.covariance.diagonal().cwiseSqrt();
  prediction.rotation_sigma_deg = sigma.head<3>();
  prediction.translation_sigma_mm = sigma.tail<3>();
  FindWorstAxis(options.adjuster.observability, &prediction);
  return prediction;
}

std::vector<CandidateStation> CandidateStations(const SurveyTarget& target,
                                                const std::vector<colmap::Rigid3d>& stations,
                                                const SurveyPlanOptions& options) {
  THROW_CHECK(options.Check());
  const Eigen::Vector3d& center = target.center;
  const double distance = MeanStationDistance(target, stations);
  double mean_height = 0;
  for (const colmap::Rigid3d& s : stations) mean_height += colmap::Inverse(s).translation.z();
  mean_height /= stations.size();
  const double look_height = target.ground_z + std::min(1.2, 0.5 * target.height);
  std::vector<CandidateStation> candidates;
  for (int k = 0; k < options.num_candidate_positions; ++k) {
    const double azimuth = 2 * M_PI * (k + 0.5) / options.num_candidate_positions;
    const Eigen::Vector2d ground =
        center.head<2>() + distance * Eigen::Vector2d(std::cos(azimuth), std::sin(azimuth));
    const Eigen::Vector3d level_eye(ground.x(), ground.y(), mean_height);
    const Eigen::Vector3d look_at(center.x(), center.y(), look_height);
    candidates.push_back(
        {CamLookingAt(level_eye, look_at, 0),
         Describe("level", azimuth * 180 / M_PI, distance, ", at the plan's height"),
         {}});
    // Tilted: low, looking up past the structure's middle, rolled.
    const Eigen::Vector3d low_eye(
        ground.x(), ground.y(), target.ground_z + options.tilted_height_m);
    const Eigen::Vector3d up_target =
        look_at +
        distance * std::tan(options.candidate_tilt_deg * M_PI / 180) * Eigen::Vector3d::UnitZ();
    std::ostringstream how;
    how << ", " << options.tilted_height_m << " m high, pitched up and rolled by "
        << options.candidate_tilt_deg << " deg";
    candidates.push_back({CamLookingAt(low_eye, up_target, options.candidate_tilt_deg),
                          Describe("tilted", azimuth * 180 / M_PI, distance, how.str().c_str()),
                          {}});
  }
  return candidates;
}

SurveyPlan PlanSurvey(const SurveyTarget& target,
                      const std::vector<colmap::Rigid3d>& stations,
                      const SurveyPlanOptions& options,
                      const std::function<void(int, int)>& progress) {
  SurveyPlan plan;
  plan.candidates = CandidateStations(target, stations, options);
  const int total = 1 + static_cast<int>(plan.candidates.size());
  plan.planned = PredictCalibration(target, stations, options);
  if (progress) progress(1, total);
  for (size_t k = 0; k < plan.candidates.size(); ++k) {
    std::vector<colmap::Rigid3d> extended = stations;
    extended.push_back(plan.candidates[k].cam_from_world);
    plan.candidates[k].prediction = PredictCalibration(target, extended, options);
    if (progress) progress(static_cast<int>(k) + 2, total);
  }
  std::stable_sort(plan.candidates.begin(),
                   plan.candidates.end(),
                   [](const CandidateStation& a, const CandidateStation& b) {
                     return a.prediction.worst_ratio < b.prediction.worst_ratio;
                   });
  return plan;
}

}  // namespace sim
}  // namespace colmap_lidar
