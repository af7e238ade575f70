// The colmap-lidar command-line dispatcher: `colmap-lidar COMMAND [--options]`, as COLMAP's `colmap`.
// This executable (not the bridge library) is the only place that links the simulator.
#include "bridge/exe/commands.h"
#include "bridge/exe/simulator_commands.h"
#include "bridge/exe/survey_planner_command.h"

#include "colmap/util/logging.h"
#include "colmap/util/version.h"

#include <ceres/version.h>
#include <opencv2/core/version.hpp>
#include <pcl/pcl_config.h>

#include <cstring>
#include <exception>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <string>

namespace colmap_lidar {
namespace {

using CommandFunc = int (*)(int, char**);

struct Command {
  const char* name;
  CommandFunc func;
  const char* help;
};

int RunHelp(int argc, char** argv);
int RunVersion(int argc, char** argv);

const Command kGeneralCommands[] = {
    {"help", &RunHelp, "List the commands"},
    {"version", &RunVersion, "Print colmap-lidar's version and the COLMAP it links"},
};

const Command kDataCommands[] = {
    {"database_creator",
     &RunDatabaseCreator,
     "Create a COLMAP database (or extend one) with colmap-lidar's tables"},
    {"database_info",
     &RunDatabaseInfo,
     "Summarise a database: COLMAP's tables and depth priors, LiDAR frames, "
     "rig"},
    {"import_dataset",
     &RunImportDataset,
     "Import a station dataset into a COLMAP database (camera, SIFT, "
     "matches, rig, LiDAR frames)"},
    {"import_kitti",
     &RunImportKitti,
     "Convert a KITTI raw drive or odometry sequence into a station dataset (with its "
     "references)"},
    {"simulate_dataset",
     &RunSimulateDataset,
     "Simulate a stereo + LiDAR station dataset with ground truth"},
    {"plan_survey",
     &RunPlanSurvey,
     "Predict the calibration of planned stations before field work; the best extra station"},
};

const Command kStepCommands[] = {
    {"pipeline", &RunPipeline, "Run every step on a dataset into a workspace (restartable)"},
    {"stereo_depth", &RunStereoDepth, "SGM stereo depth maps per station in the left image grid"},
    {"depth_prior_extractor",
     &RunDepthPriorExtractor,
     "Depth priors (d, sigma_d) of the database's keypoints from stereo "
     "depth"},
    {"lidar_registrator",
     &RunLidarRegistrator,
     "Register all station clouds and build the LiDAR pose graph"},
    {"select_frames",
     &RunSelectFrames,
     "Choose the frames of a drive that go on to the camera steps (spacing by distance and "
     "turn)"},
    {"deskew_sweeps",
     &RunDeskewSweeps,
     "De-skew the sweeps of a moving platform with a model's trajectory and cam_from_lidar"},
    {"pose_initializer",
     &RunPoseInitializer,
     "Initial station poses, cam_from_lidar and landmarks (a metric COLMAP "
     "model)"},
    {"joint_adjuster",
     &RunJointAdjuster,
     "Joint bundle adjustment: poses, landmarks and cam_from_lidar with "
     "depth priors and LiDAR"},
    {"densifier",
     &RunDensifier,
     "Dense model: stereo depth refined by LiDAR, fused.ply, lidar_map.ply, "
     "COLMAP dense workspace"},
    {"calibrate_edges",
     &RunCalibrateEdges,
     "cam_from_lidar from image edges and LiDAR depth discontinuities (Levinson & Thrun)"},
};

const Command kEvaluationCommands[] = {
    {"evaluate_model",
     &RunEvaluateModel,
     "Accuracy, completeness and density of a cloud against the true "
     "surface"},
    {"evaluate_calibration",
     &RunEvaluateCalibration,
     "Error of cam_from_lidar and of station poses against ground truth"},
    {"evaluate_trajectory",
     &RunEvaluateTrajectory,
     "Relative (KITTI) and absolute errors of a trajectory against a reference; plots"},
    {"evaluate_depth_priors",
     &RunEvaluateDepthPriors,
     "Depth priors against the true depth maps, in units of their sigma"},
    {"evaluate_dense_depth",
     &RunEvaluateDenseDepth,
     "Coverage and error of the dense depth maps against the true depth maps"},
};

// The groups in the order `help` lists them.
struct CommandGroup {
  const char* title;  // empty: no heading
  const Command* begin;
  const Command* end;
};

const CommandGroup kCommandGroups[] = {
    {"", std::begin(kGeneralCommands), std::end(kGeneralCommands)},
    {"Data: databases, datasets, simulation, survey plans",
     std::begin(kDataCommands),
     std::end(kDataCommands)},
    {"Steps (each also runs inside `pipeline`)",
     std::begin(kStepCommands),
     std::end(kStepCommands)},
    {"Evaluation against a reference or the simulator's truth",
     std::begin(kEvaluationCommands),
     std::end(kEvaluationCommands)},
};

// The command called `name`, or nullptr.
const Command* FindCommand(const std::string& name) {
  for (const CommandGroup& group : kCommandGroups) {
    for (const Command* command = group.begin; command != group.end; ++command) {
      if (name == command->name) return command;
    }
  }
  return nullptr;
}

std::string VersionString() {
  return "colmap-lidar " COLMAP_LIDAR_VERSION " (" + colmap::GetVersionInfo() +
         ", Ceres " CERES_VERSION_STRING ", PCL " PCL_VERSION_PRETTY ", OpenCV " CV_VERSION ")";
}

int RunHelp(int, char**) {
  std::cout << VersionString() << "\n\n"
            << "Usage: colmap-lidar COMMAND [--option value ...]\n"
            << "       colmap-lidar COMMAND --help   (options of a command)\n"
            << "Options may also come from an .ini file: --project_path FILE\n\n"
            << "Commands:\n";
  for (const CommandGroup& group : kCommandGroups) {
    if (*group.title) std::cout << "\n" << group.title << ":\n";
    for (const Command* command = group.begin; command != group.end; ++command) {
      std::cout << "  " << std::left << std::setw(24) << command->name << command->help << "\n";
    }
  }
  return EXIT_SUCCESS;
}

int RunVersion(int, char**) {
  std::cout << VersionString() << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace
}  // namespace colmap_lidar

int main(int argc, char** argv) {
  colmap::InitializeGlog(argv);
  FLAGS_alsologtostderr = true;
  if (argc < 2) {
    colmap_lidar::RunHelp(argc, argv);
    return EXIT_FAILURE;
  }
  const std::string name = argv[1];
  if (const colmap_lidar::Command* command = colmap_lidar::FindCommand(name)) {
    try {
      return command->func(argc - 1, argv + 1);
    } catch (const std::exception& error) {
      std::cerr << "ERROR: " << name << ": " << error.what() << std::endl;
      return EXIT_FAILURE;
    }
  }
  std::cerr << "ERROR: unknown command '" << name << "'. Run `colmap-lidar help` for the list."
            << std::endl;
  return EXIT_FAILURE;
}
