// evaluate_trajectory: a trajectory against a reference
// (bridge/evaluation/trajectory_evaluation.h).
#include "bridge/evaluation/trajectory_evaluation.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"

#include "colmap/controllers/option_manager.h"

#include <iostream>

namespace colmap_lidar {

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

int RunEvaluateTrajectory(int argc, char** argv) {
  TrajectoryEvaluationStepOptions options;
  std::string lengths, alignment = "rigid";
  colmap::OptionManager manager;
  manager.AddRequiredOption("trajectory_path",
                            &options.trajectory_path,
                            "lidar_poses.txt, a COLMAP model folder, KITTI or TUM poses");
  manager.AddRequiredOption(
      "reference_path", &options.reference_path, "e.g. DATASET/ground_truth/cam_from_world.txt");
  manager.AddRequiredOption("output_path", &options.output_path, "folder for metrics.json, PNGs");
  manager.AddDefaultOption("trajectory_format",
                           &options.trajectory_format,
                           "auto, colmap, named_world_from_sensor, named_sensor_from_world, "
                           "kitti, tum");
  manager.AddDefaultOption("reference_format", &options.reference_format, "as trajectory_format");
  manager.AddDefaultOption("reference_sensor_from_sensor_path",
                           &options.reference_sensor_from_sensor_path,
                           "pose file taking the reference to the trajectory's sensor (e.g. "
                           "ground_truth/cam_from_lidar.txt for lidar_poses.txt)");
  manager.AddDefaultOption("timestamps_path",
                           &options.timestamps_path,
                           "a dataset whose timestamps.txt times named poses (to match TUM files)");
  manager.AddDefaultOption("alignment", &alignment, "rigid or similarity (monocular)");
  manager.AddDefaultOption("lengths_m", &lengths, "segment lengths; empty: 10, 20, ... m");
  manager.AddDefaultOption("max_time_difference_s", &options.max_time_difference_s);
  manager.Parse(argc, argv);
  options.lengths_m = ParsePositiveNumbers(lengths);
  THROW_CHECK(lengths.empty() || !options.lengths_m.empty())
      << "--lengths_m must be comma-separated positive lengths in metres, not '" << lengths << "'";
  options.alignment = TrajectoryAlignmentFromName(alignment);
  RunEvaluateTrajectoryStep(options);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
