#include "bridge/evaluation/calibration_evaluation.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "lidar/model_evaluation.h"
#include "lidar/plot.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/util/misc.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <iomanip>
#include <iostream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

std::string MillimetreLabel(double threshold_m) {
  std::ostringstream label;
  label << std::setprecision(4) << threshold_m * 1000;
  return label.str() + "mm";
}

}  // namespace

std::vector<double> ParsePositiveNumbers(const std::string& csv) {
  std::vector<double> numbers;
  for (const std::string& token : colmap::CSVToVector<std::string>(csv)) {
    size_t used = 0;
    double value = 0;
    try {
      value = std::stod(token, &used);
    } catch (const std::exception&) {
      return {};
    }
    if (used != token.size() || !(value > 0)) return {};
    numbers.push_back(value);
  }
  return numbers;
}

void AddModelEvaluationOptions(const std::string& prefix,
                               colmap::OptionManager* manager,
                               ModelEvaluationOptions* options) {
  PrefixedOptions add(manager, prefix);
  add.Add("align_icp", &options->align_icp, "rigid point-to-plane ICP first");
  add.Add("crop_distance_m", &options->crop_distance_m);
}

int RunEvaluateModel(int argc, char** argv) {
  std::string model_path, ground_truth_path, output_path, thresholds = "0.002,0.005,0.01";
  std::string truth_from_model_path;
  ModelEvaluationOptions options;
  colmap::OptionManager manager;
  manager.AddRequiredOption("model_path", &model_path, "reconstructed cloud (.ply/.pcd)");
  manager.AddRequiredOption("ground_truth_path", &ground_truth_path, "surface.ply with normals");
  manager.AddRequiredOption("output_path", &output_path, "directory for metrics.json and plots");
  manager.AddDefaultOption("truth_from_model",
                           &truth_from_model_path,
                           "pose file moving the model into the truth's frame first "
                           "(evaluate_calibration writes one)");
  AddModelEvaluationOptions("", &manager, &options);
  manager.AddDefaultOption("thresholds_m", &thresholds, "comma-separated, metres");
  manager.Parse(argc, argv);
  options.thresholds_m = ParsePositiveNumbers(thresholds);
  THROW_CHECK(!options.thresholds_m.empty())
      << "--thresholds_m must be comma-separated numbers in metres, not '" << thresholds << "'";
  RunEvaluateModelStep(model_path, ground_truth_path, truth_from_model_path, output_path, options);
  return EXIT_SUCCESS;
}

namespace {

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

int RunEvaluateCalibration(int argc, char** argv) {
  std::string dataset_path, input_path, cam_from_lidar_path, output_path, alignment = "rigid";
  colmap::OptionManager manager;
  manager.AddRequiredOption("dataset_path", &dataset_path, "dataset with ground_truth/");
  manager.AddRequiredOption("input_path", &input_path, "sparse COLMAP model");
  manager.AddDefaultOption("cam_from_lidar",
                           &cam_from_lidar_path,
                           "estimate (qw qx qy qz tx ty tz); default INPUT/cam_from_lidar.txt");
  manager.AddDefaultOption("output_path", &output_path, "directory for metrics.json (optional)");
  manager.AddDefaultOption("alignment", &alignment, "rigid | similarity");
  manager.Parse(argc, argv);
  RunEvaluateCalibrationStep(dataset_path,
                             input_path,
                             cam_from_lidar_path,
                             output_path,
                             TrajectoryAlignmentFromName(alignment));
  return EXIT_SUCCESS;
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

}  // namespace colmap_lidar
