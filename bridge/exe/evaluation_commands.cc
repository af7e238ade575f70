#include "bridge/evaluation/calibration_evaluation.h"
#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/model_evaluation.h"

#include "colmap/util/misc.h"

#include <filesystem>

namespace colmap_lidar {
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
                               CommandOptions* manager,
                               ModelEvaluationOptions* options) {
  PrefixedOptions add(manager, prefix);
  add.Add("align_icp", &options->align_icp, "rigid point-to-plane ICP first");
  add.Add("crop_distance_m", &options->crop_distance_m);
}

int RunEvaluateModel(int argc, char** argv) {
  std::string model_path, ground_truth_path, output_path, thresholds = "0.002,0.005,0.01";
  std::string truth_from_model_path;
  ModelEvaluationOptions options;
  CommandOptions manager;
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

int RunEvaluateCalibration(int argc, char** argv) {
  std::string dataset_path, input_path, cam_from_lidar_path, output_path;
  TrajectoryAlignment alignment = TrajectoryAlignment::kRigid;
  CommandOptions manager;
  manager.AddRequiredOption("dataset_path", &dataset_path, "dataset with ground_truth/");
  manager.AddRequiredOption("input_path", &input_path, "sparse COLMAP model");
  manager.AddDefaultOption("cam_from_lidar",
                           &cam_from_lidar_path,
                           "estimate (qw qx qy qz tx ty tz); default INPUT/cam_from_lidar.txt");
  manager.AddDefaultOption("output_path", &output_path, "directory for metrics.json (optional)");
  manager.AddChoiceOption("alignment", &alignment, kTrajectoryAlignmentNames);
  manager.Parse(argc, argv);
  RunEvaluateCalibrationStep(dataset_path, input_path, cam_from_lidar_path, output_path, alignment);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
