// colmap-lidar joint_adjuster: the joint problem on a COLMAP sparse model
// (bridge/joint/joint_adjuster.h).
#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "bridge/initialization/lidar_registration_files.h"
#include "bridge/joint/association_settling.h"
#include "bridge/joint/joint_adjuster.h"
#include "bridge/joint/joint_problem_data.h"
#include "bridge/joint/start_departure.h"
#include "bridge/pipeline/joint_step.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/plot.h"

#include "colmap/scene/reconstruction.h"

#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

namespace colmap_lidar {

namespace {

// --hold_translation: comma-separated camera axes ("y", "x,z").
std::array<bool, 3> ParseHeldAxes(const std::string& text) {
  std::array<bool, 3> held = {false, false, false};
  std::stringstream stream(text);
  std::string axis;
  while (std::getline(stream, axis, ',')) {
    if (axis.size() == 1 && axis[0] >= 'x' && axis[0] <= 'z') {
      held[axis[0] - 'x'] = true;
    } else if (!axis.empty()) {
      throw std::invalid_argument("--hold_translation: unknown axis '" + axis +
                                  "' (a comma-separated subset of x,y,z)");
    }
  }
  return held;
}

}  // namespace

void AddJointAdjusterOptions(const std::string& prefix,
                             CommandOptions* manager,
                             JointAdjusterStepOptions* options) {
  PrefixedOptions add(manager, prefix);
  JointAdjusterOptions& adjuster = options->adjuster;
  add.Add("estimate_variance_components",
          &adjuster.estimate_variance_components,
          "weight each data group by its variance factor estimated with the solve");
  add.Add("estimate_time_offset",
          &options->estimate_time_offset,
          "on a moving platform, estimate the LiDAR clock's offset from the cameras");
  add.Add("estimate_depth_bias",
          &adjuster.estimate_depth_bias,
          "estimate the stereo depth's disparity bias field (offset, x and y slopes) against the "
          "LiDAR (E_m)");
  add.Add("estimate_oblique_offset",
          &adjuster.estimate_oblique_offset,
          "estimate the landmarks' offset from surfaces seen at grazing angles (E_m), "
          "experimental");
  add.Add("hold_rotation", &adjuster.hold_rotation, "hold cam_from_lidar's rotation at its start");
  std::array<bool, 3>* held = &adjuster.hold_translation;
  manager->AddParsedOption(
      prefix + "hold_translation",
      "",
      [held](const std::string& text) { *held = ParseHeldAxes(text); },
      "camera axes of cam_from_lidar's translation held at their start, e.g. y or x,z");
  add.Add("hold_rotation_deg",
          &adjuster.hold_rotation_deg,
          "sigma above which a rotation direction is held (at rig.json's guess, else at its start) "
          "and named undetermined");
  add.Add("hold_translation_mm",
          &adjuster.hold_translation_mm,
          "sigma above which a translation direction is held (at rig.json's guess, else at its "
          "start) and named undetermined");
  add.Add("write_text", &options->write_text, "also write cameras.txt, images.txt, points3D.txt");
}

namespace {

// Options joint_adjuster no longer takes, with what decides their value now.
struct RemovedOption {
  const char* name;
  const char* replacement;
};

constexpr char kWeightsEstimated[] =
    "each data group's weight is estimated with the solve (variance components)";
constexpr char kGatesFixed[] = "the outlier gates are fixed (docs/joint_adjuster.md lists them)";
constexpr char kNoLoss[] =
    "no robust loss: the outlier gates remove outliers (docs/joint_adjuster.md)";
constexpr char kRoundsFixed[] =
    "the association rounds run until cam_from_lidar stops moving, at most 10; report.json "
    "'association' says whether they settled (docs/joint_adjuster.md)";
constexpr char kSamplingFixed[] =
    "the LiDAR association's sampling is fixed (docs/joint_adjuster.md)";
constexpr char kCovarianceFixed[] =
    "the covariance model is fixed (docs/joint_adjuster.md, Uncertainty)";
constexpr char kFromMotion[] = "decided from the stations' motion (docs/joint_adjuster.md)";

constexpr RemovedOption kRemovedOptions[] = {
    {"depth_weight", kWeightsEstimated},
    {"lidar_weight", kWeightsEstimated},
    {"landmark_lidar_weight", kFromMotion},
    {"sigma_landmark_lidar_m", kWeightsEstimated},
    {"loss", kNoLoss},
    {"loss_scale", kNoLoss},
    {"max_reprojection_error_px", kGatesFixed},
    {"max_depth_error_sigmas", kGatesFixed},
    {"depth_gate_from_residual_scale", kGatesFixed},
    {"max_depth_error_m", kGatesFixed},
    {"max_point_to_plane_m", kGatesFixed},
    {"max_landmark_plane_m", kGatesFixed},
    {"max_landmark_plane_sigmas", kGatesFixed},
    {"association_max_curvature", kGatesFixed},
    {"max_outlier_iterations", kGatesFixed},
    {"first_depth_prior_round", kRoundsFixed},
    {"num_association_rounds", kRoundsFixed},
    {"max_association_rounds", kRoundsFixed},
    {"round_convergence_deg", kRoundsFixed},
    {"round_convergence_mm", kRoundsFixed},
    {"initial_association_distance_m", kGatesFixed},
    {"association_max_distance_m", kGatesFixed},
    {"max_num_iterations", "each solve runs up to Ceres' fixed iteration limit (100)"},
    {"num_samples_per_pair", kSamplingFixed},
    {"normal_space_sampling", kSamplingFixed},
    {"max_lidar_neighbors", kSamplingFixed},
    {"min_image_pair_inliers", kSamplingFixed},
    {"compress_lidar_blocks", "the LiDAR term is always passed to Ceres in its compressed form"},
    {"free_lidar_drive_roll", "the LiDAR term and the others share one cam_from_lidar"},
    {"extrinsic_prior_sigma_m",
     "a prior on cam_from_lidar comes only from rig.json's cam_from_lidar_guess_sigma"},
    {"hold_unobservable",
     "undetermined directions are always held at their start and named (hold_rotation_deg, "
     "hold_translation_mm)"},
    {"stereo_scale_sigma", kCovarianceFixed},
    {"two_way_lidar_clusters", kCovarianceFixed},
    {"unobservable_translation_mm", kCovarianceFixed},
    {"unobservable_rotation_deg", kCovarianceFixed},
    {"use_stereo_alignment",
     "the stereo-LiDAR alignment is the start, not a measurement in the cost"},
    {"vertical_alignment", kFromMotion},
    {"sigma_lidar_m",
     "the LiDAR's range noise is rig.json's lidar.range_noise_m (default 0.02 m), the starting "
     "weight of E_l that the estimated variance factor scales"},
};

}  // namespace

namespace {

// The option keys of a COLMAP project file (boost's ini syntax): "key = value" lines, a key under a
// "[Section]" header named "Section.key".
std::vector<std::string> ProjectFileKeys(const std::string& path) {
  std::ifstream file(path);
  if (path.empty()) throw std::invalid_argument("--project_path needs a file");
  if (!file) throw std::invalid_argument("cannot read the project file " + path);
  std::vector<std::string> keys;
  std::string section;
  for (std::string line; std::getline(file, line);) {
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    if (line[first] == '[') {
      section = line.substr(first + 1, line.find(']') - first - 1) + ".";
      continue;
    }
    const std::string key = line.substr(first, line.find('=') - first);
    keys.push_back(section + key.substr(0, key.find_last_not_of(" \t") + 1));
  }
  return keys;
}

// The removed option `key` names (with `prefix`), or null.
const RemovedOption* FindRemovedOption(const std::string& key, const std::string& prefix) {
  for (const RemovedOption& removed : kRemovedOptions) {
    if (key == prefix + removed.name) return &removed;
  }
  return nullptr;
}

}  // namespace

void RefuseRemovedJointAdjusterOptions(int argc, char** argv, const std::string& prefix) {
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument.rfind("--", 0) != 0) continue;
    const std::string key = argument.substr(2, argument.find('=') - 2);
    if (const RemovedOption* removed = FindRemovedOption(key, prefix)) {
      throw std::invalid_argument("--" + key + " is no longer an option: " + removed->replacement);
    }
    if (key != "project_path") continue;
    const std::string path = argument.find('=') != std::string::npos
                                 ? argument.substr(argument.find('=') + 1)
                                 : (i + 1 < argc ? argv[i + 1] : "");
    for (const std::string& file_key : ProjectFileKeys(path)) {
      if (const RemovedOption* removed = FindRemovedOption(file_key, prefix)) {
        throw std::invalid_argument(path + ": " + file_key +
                                    " is no longer an option: " + removed->replacement);
      }
    }
  }
}

int RunJointAdjuster(int argc, char** argv) {
  std::string dataset_path, registration_path;
  JointAdjusterPaths paths;
  JointAdjusterStepOptions joint;
  CommandOptions options;
  options.AddDatabaseOptions();
  options.AddRequiredOption("input_path", &paths.input_path);
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddRequiredOption("output_path", &paths.output_path);
  options.AddChoiceOption("mode", &joint.adjuster.mode, kJointModeNames);
  options.AddDefaultOption("cam_from_lidar",
                           &paths.cam_from_lidar_path,
                           "qw qx qy qz tx ty tz file; default: INPUT/cam_from_lidar.txt, else "
                           "rig.json's cam_from_lidar_guess");
  options.AddDefaultOption("registration_path", &registration_path, kRegistrationPathHelp);
  AddJointAdjusterOptions("", &options, &joint);
  RefuseRemovedJointAdjusterOptions(argc, argv, "");
  options.Parse(argc, argv);
  THROW_CHECK(joint.Check());  // before any file is read
  paths.database_path = *options.database_path;
  RunJointAdjusterStep(
      WithRegistratorClouds(ReadStationDataset(dataset_path), registration_path), paths, joint);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
