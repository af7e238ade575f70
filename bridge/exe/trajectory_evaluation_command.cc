// evaluate_trajectory: a trajectory against a reference
// (bridge/evaluation/trajectory_evaluation.h).
#include "bridge/evaluation/trajectory_evaluation.h"
#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"

#include <iostream>

namespace colmap_lidar {

int RunEvaluateTrajectory(int argc, char** argv) {
  TrajectoryEvaluationStepOptions options;
  std::string lengths;
  CommandOptions manager;
  manager.AddRequiredOption("trajectory_path",
                            &options.trajectory_path,
                            "lidar_poses.txt, a COLMAP model folder, KITTI or TUM poses");
  manager.AddRequiredOption(
      "reference_path", &options.reference_path, "e.g. DATASET/ground_truth/cam_from_world.txt");
  manager.AddRequiredOption("output_path", &options.output_path, "folder for metrics.json, PNGs");
  manager.AddChoiceOption("trajectory_format",
                          &options.trajectory_format,
                          kTrajectorySourceNames,
                          "auto: a folder is a COLMAP model, a file's format is detected");
  manager.AddChoiceOption("reference_format", &options.reference_format, kTrajectorySourceNames);
  manager.AddDefaultOption("reference_sensor_from_sensor_path",
                           &options.reference_sensor_from_sensor_path,
                           "pose file taking the reference to the trajectory's sensor (e.g. "
                           "ground_truth/cam_from_lidar.txt for lidar_poses.txt)");
  manager.AddDefaultOption("timestamps_path",
                           &options.timestamps_path,
                           "a dataset whose timestamps.txt times named poses (to match TUM files)");
  manager.AddChoiceOption(
      "alignment", &options.alignment, kTrajectoryAlignmentNames, "similarity: monocular");
  manager.AddDefaultOption("lengths_m", &lengths, "segment lengths; empty: 10, 20, ... m");
  manager.AddDefaultOption("max_time_difference_s", &options.max_time_difference_s);
  manager.Parse(argc, argv);
  options.lengths_m = ParsePositiveNumbers(lengths);
  THROW_CHECK(lengths.empty() || !options.lengths_m.empty())
      << "--lengths_m must be comma-separated positive lengths in metres, not '" << lengths << "'";
  RunEvaluateTrajectoryStep(options);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
