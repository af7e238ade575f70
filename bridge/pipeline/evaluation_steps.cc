#include "bridge/pipeline/evaluation_steps.h"

#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "lidar/plot.h"
#include "lidar/util/atomic_file.h"

#include "colmap/scene/reconstruction.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

namespace colmap_lidar {

namespace fs = std::filesystem;

namespace {

std::string MillimetreLabel(double threshold_m) {
  std::ostringstream label;
  label << std::setprecision(4) << threshold_m * 1000;
  return label.str() + "mm";
}

// The console summary of a model evaluation with evaluated points.
void PrintModelEvaluation(const ModelEvaluation& result) {
  std::cout << std::fixed << std::setprecision(2) << "evaluate_model: mean " << result.mean * 1000
            << " mm, median " << result.median * 1000 << " mm, RMSE " << result.rmse * 1000
            << " mm, p95 " << result.p95 * 1000 << " mm over " << result.num_evaluated
            << " points; density " << result.density_points_per_cm2 << " points/cm^2" << std::endl;
  for (const auto& at : result.at_thresholds) {
    std::cout << "  at " << MillimetreLabel(at.threshold) << ": completeness " << at.completeness
              << ", precision " << at.precision << ", F " << at.f_score << std::endl;
  }
}

// evaluate_model's metrics.json.
nlohmann::json ModelMetricsJson(const std::string& model_path,
                                const ModelEvaluation& result,
                                const ModelEvaluationOptions& options) {
  nlohmann::json metrics;
  metrics["model_path"] = model_path;
  metrics["num_model_points"] = result.num_model_points;
  metrics["num_evaluated"] = result.num_evaluated;
  metrics["icp_aligned"] = options.align_icp;
  metrics["icp_converged"] = result.icp_converged;
  metrics["icp_rotation_deg"] =
      Eigen::AngleAxisd(result.truth_from_model.linear()).angle() * 180 / M_PI;
  metrics["icp_translation_m"] = result.truth_from_model.translation().norm();
  // No evaluated point: the statistics are null, never zeros that read as a perfect model.
  const bool measured = result.num_evaluated > 0;
  for (const auto& [key, value] : {std::pair{"mean_m", result.mean},
                                   {"median_m", result.median},
                                   {"rmse_m", result.rmse},
                                   {"p90_m", result.p90},
                                   {"p95_m", result.p95},
                                   {"p99_m", result.p99},
                                   {"max_m", result.max}}) {
    metrics[key] = measured ? nlohmann::json(value) : nlohmann::json();
  }
  for (const auto& at : result.at_thresholds) {
    const std::string label = MillimetreLabel(at.threshold);
    metrics["completeness_" + label] = at.completeness;
    metrics["precision_" + label] = at.precision;
    metrics["f_score_" + label] = at.f_score;
  }
  metrics["density_points_per_cm2"] = result.density_points_per_cm2;
  return metrics;
}

// The evaluated points, aligned, coloured by error (blue 0 -> red at the 95th percentile).
PointCloud ErrorColoredCloud(const PointCloud& model, const ModelEvaluation& result) {
  PointCloud coloured;
  coloured.Reserve(result.num_evaluated, false, true, false);
  for (size_t k = 0; k < result.num_evaluated; ++k) {
    coloured.points.push_back(result.truth_from_model * model.points[result.evaluated_indices[k]]);
    coloured.colors.push_back(ErrorColor(result.distances[k], result.p95));
  }
  return coloured;
}

// evaluate_calibration's metrics.json.
nlohmann::json CalibrationMetricsJson(const CalibrationEvaluation& result) {
  nlohmann::json metrics;
  metrics["cam_from_lidar_rotation_error_deg"] = result.cam_from_lidar_rotation_error_deg;
  metrics["cam_from_lidar_translation_error_mm"] = result.cam_from_lidar_translation_error_mm;
  for (int k = 0; k < 3; ++k) {
    metrics[std::string("cam_from_lidar_translation_error_") + "xyz"[k] + "_mm"] =
        result.cam_from_lidar_translation_error_in_cam_mm[k];
  }
  if (!result.alignment) return metrics;
  metrics["pose_alignment"] = TrajectoryAlignmentName(*result.alignment);
  metrics["pose_alignment_scale"] = result.alignment_scale;
  metrics["num_stations_evaluated"] = result.num_stations_evaluated;
  metrics["missing_stations"] = result.missing_stations;
  metrics["pose_rotation_error_mean_deg"] = result.mean_rotation_error_deg;
  metrics["pose_rotation_error_max_deg"] = result.max_rotation_error_deg;
  metrics["pose_position_error_mean_mm"] = result.mean_position_error_mm;
  metrics["pose_position_error_max_mm"] = result.max_position_error_mm;
  for (const auto& [name, error] : result.position_error_mm) {
    metrics["station_" + name + "_position_error_mm"] = error;
    metrics["station_" + name + "_rotation_error_deg"] = result.rotation_error_deg.at(name);
  }
  return metrics;
}

// evaluate_calibration's console summary.
void PrintCalibrationEvaluation(const CalibrationEvaluation& result) {
  std::cout << std::fixed << std::setprecision(4) << "evaluate_calibration: cam_from_lidar error "
            << result.cam_from_lidar_rotation_error_deg << " deg, " << std::setprecision(2)
            << result.cam_from_lidar_translation_error_mm << " mm";
  if (!result.alignment) {
    std::cout << " (against the dataset's reference; no true station poses)" << std::endl;
  } else {
    std::cout << "; station poses (" << TrajectoryAlignmentName(*result.alignment) << " alignment, "
              << result.num_stations_evaluated << " stations): mean "
              << result.mean_position_error_mm << " mm / " << std::setprecision(4)
              << result.mean_rotation_error_deg << " deg, max " << std::setprecision(2)
              << result.max_position_error_mm << " mm" << std::endl;
  }
  if (!result.missing_stations.empty()) {
    std::cout << "evaluate_calibration: " << result.missing_stations.size()
              << " stations of the truth are not in the model" << std::endl;
  }
}

nlohmann::json StatisticsJson(const DenseDepthStatistics& s) {
  return {{"num_pixels", s.num_pixels},
          {"num_with_depth", s.num_with_depth},
          {"num_compared", s.num_compared},
          {"coverage", s.coverage},
          {"mean_error_m", s.mean_error_m},
          {"median_abs_error_m", s.median_abs_error_m},
          {"p90_abs_error_m", s.p90_abs_error_m},
          {"p99_abs_error_m", s.p99_abs_error_m},
          {"median_abs_relative_error", s.median_abs_relative_error},
          {"within_1cm", s.within_1cm},
          {"within_5cm", s.within_5cm}};
}

nlohmann::json StatisticsJson(const DepthPriorStatistics& statistics) {
  nlohmann::json json;
  json["num_priors"] = statistics.num_priors;
  json["median_abs_relative_error"] = statistics.median_abs_relative_error;
  json["mean_relative_error"] = statistics.mean_relative_error;
  json["mean_normalized_error"] = statistics.mean_normalized_error;
  json["within_1_sigma"] = statistics.within_1_sigma;
  json["within_2_sigma"] = statistics.within_2_sigma;
  json["within_3_sigma"] = statistics.within_3_sigma;
  json["beyond_10_sigma"] = statistics.beyond_10_sigma;
  return json;
}

void PrintStatistics(const std::string& label, const DepthPriorStatistics& statistics) {
  std::cout << std::fixed << std::setprecision(1) << "  " << label << ": " << statistics.num_priors
            << " priors, median |error| " << 100 * statistics.median_abs_relative_error
            << " % of the depth, mean error " << 100 * statistics.mean_relative_error << " % ("
            << std::setprecision(2) << statistics.mean_normalized_error
            << " sigma); within 1/2/3 sigma " << std::setprecision(1)
            << 100 * statistics.within_1_sigma << " / " << 100 * statistics.within_2_sigma << " / "
            << 100 * statistics.within_3_sigma
            << " % (Gaussian 68.3 / 95.4 / 99.7), beyond 10 sigma "
            << 100 * statistics.beyond_10_sigma << " %" << std::endl;
}

}  // namespace

void RunEvaluateModelStep(const std::string& model_path,
                          const std::string& ground_truth_path,
                          const std::string& truth_from_model_path,
                          const std::string& output_path,
                          const ModelEvaluationOptions& options) {
  // Inputs first: a missing or bad cloud must not leave an output folder behind.
  PointCloud model = ReadPointCloud(model_path);
  if (!truth_from_model_path.empty()) {
    const colmap::Rigid3d truth_from_model = ReadPoseFile(truth_from_model_path);
    for (Eigen::Vector3d& point : model.points) point = truth_from_model * point;
    for (Eigen::Vector3d& normal : model.normals) {
      normal = truth_from_model.rotation * normal;
    }
  }
  const PointCloud truth = ReadPointCloud(ground_truth_path);
  THROW_CHECK(truth.HasNormals()) << ground_truth_path << " has no normals";
  std::cout << "evaluate_model: " << model.Size() << " model points against " << truth.Size()
            << " surface samples" << std::endl;
  const ModelEvaluation result = EvaluateModel(model, truth, options);

  fs::create_directories(output_path);
  WriteFileAtomically((fs::path(output_path) / "metrics.json").string(),
                      ModelMetricsJson(model_path, result, options).dump(2) + "\n");

  HistogramPlotOptions plot;
  plot.title = "Distance to the true surface";
  plot.x_label = "distance [mm]";
  plot.value_scale = 1000;
  WriteHistogramPng(
      (fs::path(output_path) / "error_histogram.png").string(), result.distances, plot);

  WritePointCloud((fs::path(output_path) / "error_colored.ply").string(),
                  ErrorColoredCloud(model, result));

  if (result.num_evaluated > 0) {
    PrintModelEvaluation(result);
  } else {
    std::cout << "evaluate_model: no model point lies within " << options.crop_distance_m
              << " m of the true surface: nothing to measure (is the model of this structure?)"
              << std::endl;
  }
  std::cout << "evaluate_model: wrote " << output_path
            << "/{metrics.json, error_histogram.png, error_colored.ply}" << std::endl;
}

void RunEvaluateCalibrationStep(const std::string& dataset_path,
                                const std::string& input_path,
                                const std::string& cam_from_lidar_path,
                                const std::string& output_path,
                                TrajectoryAlignment alignment) {
  const std::string estimate_path = cam_from_lidar_path.empty()
                                        ? (fs::path(input_path) / "cam_from_lidar.txt").string()
                                        : cam_from_lidar_path;
  const fs::path truth_dir = fs::path(dataset_path) / "ground_truth";
  std::map<std::string, colmap::Rigid3d> true_cam_from_world;
  if (fs::is_regular_file(truth_dir / "cam_from_world.txt")) {
    true_cam_from_world = ReadNamedPoses((truth_dir / "cam_from_world.txt").string());
  } else {
    std::cout << "evaluate_calibration: no " << (truth_dir / "cam_from_world.txt").string()
              << " (e.g. a KITTI drive): evaluating cam_from_lidar only, not the station poses"
              << std::endl;
  }
  const colmap::Rigid3d true_cam_from_lidar =
      ReadPoseFile((truth_dir / "cam_from_lidar.txt").string());
  const colmap::Rigid3d cam_from_lidar = ReadPoseFile(estimate_path);
  THROW_CHECK(fs::is_directory(input_path)) << "No sparse model at " << input_path;
  colmap::Reconstruction reconstruction;
  reconstruction.Read(input_path);
  const CalibrationEvaluation result = EvaluateCalibration(
      true_cam_from_lidar, cam_from_lidar, true_cam_from_world, reconstruction, alignment);

  const nlohmann::json metrics = CalibrationMetricsJson(result);
  PrintCalibrationEvaluation(result);
  if (!output_path.empty()) {
    fs::create_directories(output_path);
    WriteFileAtomically((fs::path(output_path) / "metrics.json").string(), metrics.dump(2) + "\n");
    if (!result.alignment) return;
    WritePoseFile((fs::path(output_path) / "truth_from_model.txt").string(),
                  "true_world_from_model_world by " + TrajectoryAlignmentName(*result.alignment) +
                      " alignment of the camera centres (scale " +
                      std::to_string(result.alignment_scale) +
                      " not included); qw qx qy qz tx ty tz",
                  result.truth_from_model);
  } else {
    std::cout << metrics.dump(2) << std::endl;
  }
}

bool TrajectoryEvaluationStepOptions::Check() const {
  CHECK_OPTION_GT(max_time_difference_s, 0);
  return true;
}

TrajectoryError RunEvaluateTrajectoryStep(const TrajectoryEvaluationStepOptions& options) {
  THROW_CHECK(options.Check());
  Trajectory estimate = LoadTrajectory(options.trajectory_path, options.trajectory_format);
  Trajectory reference = LoadTrajectory(options.reference_path, options.reference_format);
  if (!options.reference_sensor_from_sensor_path.empty()) {
    const colmap::Rigid3d sensor = ReadPoseFile(options.reference_sensor_from_sensor_path);
    for (colmap::Rigid3d& pose : reference.world_from_sensor) pose = pose * sensor;
  }
  if (!options.timestamps_path.empty()) {
    const StationDataset times = ReadStationDataset(options.timestamps_path);
    AttachStationTimes(times.stations, times.frame_times, &estimate);
    AttachStationTimes(times.stations, times.frame_times, &reference);
  }
  const MatchedTrajectories matched = MatchTrajectories(estimate,
                                                        options.trajectory_path,
                                                        reference,
                                                        options.reference_path,
                                                        options.max_time_difference_s);
  TrajectoryErrorOptions error_options;
  error_options.lengths_m = options.lengths_m;
  error_options.alignment = options.alignment;
  const TrajectoryError error =
      EvaluateTrajectoryError(matched.estimate, matched.reference, error_options);
  WriteTrajectoryEvaluation(options.output_path, matched, error, error_options);
  std::cout << "evaluate_trajectory: " << matched.names.size() << " frames matched by "
            << matched.matched_by << " (" << matched.num_estimate_unmatched << " of "
            << options.trajectory_path << " and " << matched.num_reference_unmatched
            << " of the reference unmatched); " << TrajectoryErrorSummary(error) << std::endl;
  return error;
}

void RunEvaluateDenseDepthStep(const std::string& dense_path,
                               const std::string& dataset_path,
                               const std::string& output_path) {
  const std::string truth_path = (fs::path(dataset_path) / "ground_truth" / "depth").string();
  const DenseDepthEvaluation evaluation = EvaluateDenseDepth(dense_path, truth_path);
  const DenseDepthStatistics& all = evaluation.all;
  std::cout << std::fixed << std::setprecision(1)
            << "evaluate_dense_depth: " << evaluation.image_names.size() << " depth maps against "
            << truth_path << " (" << evaluation.images_without_truth.size()
            << " without a true one, " << evaluation.images_of_another_size.size()
            << " of another size, not compared): depth on " << 100 * all.coverage
            << " % of the pixels; error median " << 1000 * all.median_abs_error_m << " mm, 90 % "
            << 1000 * all.p90_abs_error_m << " mm, 99 % " << 1000 * all.p99_abs_error_m
            << " mm, mean (bias) " << 1000 * all.mean_error_m << " mm; within 1 / 5 cm "
            << 100 * all.within_1cm << " / " << 100 * all.within_5cm << " %" << std::endl;

  PartialOutputFolder partial(output_path);
  nlohmann::json metrics;
  metrics["all"] = StatisticsJson(all);
  nlohmann::json per_image = nlohmann::json::object();
  for (size_t k = 0; k < evaluation.image_names.size(); ++k) {
    per_image[evaluation.image_names[k]] = StatisticsJson(evaluation.per_image[k]);
  }
  metrics["per_image"] = per_image;
  metrics["images_without_truth"] = evaluation.images_without_truth;
  metrics["images_of_another_size"] = evaluation.images_of_another_size;
  WriteFileAtomically(partial.File("metrics.json"), metrics.dump(2) + "\n");
  HistogramPlotOptions plot;
  plot.title = "Dense depth error against the true depth";
  plot.x_label = "|dense - true| [mm]";
  plot.value_scale = 1000;
  WriteHistogramPng(partial.File("error_histogram.png"), evaluation.abs_error_sample, plot);
  partial.Commit();
  std::cout << "evaluate_dense_depth: wrote " << output_path
            << "/{metrics.json, error_histogram.png}" << std::endl;
}

void RunEvaluateDepthPriorsStep(const std::string& database_path,
                                const std::string& dataset_path,
                                const std::string& output_path,
                                const DepthPriorEvaluationOptions& options) {
  const std::string truth_path = (fs::path(dataset_path) / "ground_truth" / "depth").string();
  const DepthPriorEvaluation evaluation = EvaluateDepthPriors(database_path, truth_path, options);
  std::cout << "evaluate_depth_priors: " << evaluation.errors.size() << " priors against "
            << truth_path << " (" << evaluation.num_without_true_depth
            << " on pixels without true depth, " << evaluation.images_without_truth.size()
            << " images without a true depth map)" << std::endl;
  PrintStatistics("all", evaluation.all);
  PrintStatistics("at depth edges", evaluation.at_edges);
  PrintStatistics("away from edges", evaluation.away_from_edges);
  PrintStatistics("within " + std::to_string(static_cast<int>(options.inlier_sigmas)) +
                      " sigma (what the adjuster's gate keeps)",
                  evaluation.inliers);

  fs::create_directories(output_path);
  nlohmann::json metrics;
  metrics["all"] = StatisticsJson(evaluation.all);
  metrics["at_edges"] = StatisticsJson(evaluation.at_edges);
  metrics["away_from_edges"] = StatisticsJson(evaluation.away_from_edges);
  metrics["inliers"] = StatisticsJson(evaluation.inliers);
  metrics["inlier_sigmas"] = options.inlier_sigmas;
  metrics["num_without_true_depth"] = evaluation.num_without_true_depth;
  metrics["images_without_truth"] = evaluation.images_without_truth;
  WriteFileAtomically((fs::path(output_path) / "metrics.json").string(), metrics.dump(2) + "\n");

  std::vector<double> normalized;
  for (const DepthPriorError& error : evaluation.errors) {
    normalized.push_back(std::abs(error.Normalized()));
  }
  HistogramPlotOptions plot;
  plot.title = "Depth prior error in units of its sigma";
  plot.x_label = "|prior - true| / sigma_d";
  plot.max_value = 6;
  WriteHistogramPng(
      (fs::path(output_path) / "normalized_error_histogram.png").string(), normalized, plot);
  std::cout << "evaluate_depth_priors: wrote " << output_path
            << "/{metrics.json, normalized_error_histogram.png}" << std::endl;
}

}  // namespace colmap_lidar
