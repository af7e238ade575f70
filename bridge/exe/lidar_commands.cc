// lidar_registrator and deskew_sweeps: option registration and argv parsing; the steps are
// bridge/pipeline/lidar_registration_step.h.
#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/logging.h"

#include <filesystem>

namespace colmap_lidar {
namespace fs = std::filesystem;
namespace {

// The method's choice and the odometry's options (refinement, revisits) of lidar_registrator.
void AddOdometryOptions(PrefixedOptions* options_of, LidarRegistratorStepOptions* options) {
  PrefixedOptions& add = *options_of;
  add.AddChoice("method",
                &options->method,
                kRegistrationMethodNames,
                "pairwise (BSC + RANSAC + ICP per pair), odometry (sweeps: frame-to-map ICP), "
                "auto (odometry for sweeps, pairwise for stations)");
  add.Add("odometry_max_range_m", &options->odometry.max_range_m);
  add.Add("odometry_min_range_m", &options->odometry.min_range_m, "nearer returns: the platform");
  add.Add("odometry_voxel_size_m", &options->odometry.voxel_size_m, "0: max range / 100");
  add.Add("odometry_point_to_plane",
          &options->odometry.icp.point_to_plane,
          "distance to the map's local plane where it is one (0: point-to-point, KISS-ICP)");
  add.Add("refine_neighbors",
          &options->refine_neighbors,
          "odometry: k > 0 refines the trajectory by ICP between each sweep and its next k sweeps");
  add.Add("revisits",
          &options->revisits,
          "odometry: register keyframes that revisit a place, accepted within the drift");
  add.Add("revisit_radius_m", &options->revisit.search_radius_m, "keyframes nearer than this");
  add.Add("revisit_min_path_m",
          &options->revisit.min_path_gap_m,
          "and at least this far apart along the path");
  add.Add("odometry_drift",
          &options->revisit.drift.translation,
          "the odometry's translation drift per metre travelled (1 sigma)");
  add.Add("odometry_drift_deg_per_m",
          &options->revisit.drift.rotation_deg_per_m,
          "the odometry's rotation drift (1 sigma)");
}

}  // namespace

void AddLidarRegistratorOptions(const std::string& prefix,
                                CommandOptions* manager,
                                LidarRegistratorStepOptions* options) {
  PrefixedOptions add(manager, prefix);
  StationCloudOptions& cloud = options->cloud;
  PairRegistrationOptions& pair = options->graph.pair;
  add.Add("voxel_size", &cloud.voxel_size, "ICP/normals voxel [m]");
  add.Add("feature_voxel_size", &cloud.feature_voxel_size);
  add.Add("bsc_support_radius", &cloud.bsc.support_radius);
  add.Add("max_neighbors",
          &options->max_neighbors,
          "0: all pairs; k: the k most similar stations each");
  add.Add("bridge_neighbors",
          &options->bridge_neighbors,
          "disconnected stations: register each with its k most similar of other components");
  add.Add("max_bridge_rounds", &options->graph.max_bridge_rounds);
  add.Add("sequential",
          &options->sequential,
          "k > 0: register each frame with its k successors (sweeps)");
  add.Add("min_overlap", &pair.min_overlap);
  add.Add("max_rmse_to_noise", &pair.max_rmse_to_noise, "ICP RMSE / the clouds' own plane noise");
  add.Add("max_rmse", &pair.max_rmse, "absolute cap [m]; 0: none");
  add.Add("try_identity", &pair.try_identity);
  add.Add("min_constraint_ratio", &pair.min_constraint_ratio);
  add.Add("weak_constraint_ratio", &pair.weak_constraint_ratio);
  add.Add("check_cycles", &options->graph.check_cycles);
  add.Add("max_cycle_translation_m", &options->graph.cycles.max_translation_m);
  add.Add("max_cycle_rotation_deg", &options->graph.cycles.max_rotation_deg);
  add.Add("robust_loss_sigmas", &options->graph.robust_loss_sigmas);
  add.Add("max_speed_deviation",
          &options->graph.speed.max_relative_deviation,
          "sweeps (deskew_sweeps or sequential): an edge whose speed differs from the edges' "
          "around it by more than this fraction of theirs is registered again from their "
          "velocity, and refused if that fails");
  add.Add("deskew_sweeps",
          &options->deskew_sweeps,
          "sweeps of a moving platform: de-skew them with the registered motion, register again");
  add.Add("sweep_start_azimuth_deg",
          &options->sweep_timing.start_azimuth_deg,
          "where a revolution starts (LiDAR frame; 180: behind)");
  add.Add("sweep_counter_clockwise", &options->sweep_timing.counter_clockwise);
  add.AddChoice(
      "remove_moving_points",
      &options->remove_moving_points,
      kMovingPointRemovalNames,
      "on: flag moving objects by free space and write static/<station>.pcd without them; "
      "auto: on with deskew_sweeps");
  add.Add("moving_neighbour_clouds",
          &options->moving.num_neighbour_clouds,
          "clouds compared on each side (name order)");
  add.Add("moving_margin_m", &options->moving.margin_m, "plus moving_margin_ratio x range");
  add.Add("moving_margin_ratio", &options->moving.margin_ratio);
  AddOdometryOptions(&add, options);
}

int RunDeskewSweeps(int argc, char** argv) {
  std::string dataset_path, input_path, output_path;
  CommandOptions manager;
  manager.AddRequiredOption(
      "dataset_path", &dataset_path, "raw sweeps in DATASET/lidar; rig.json with lidar.sweep");
  manager.AddRequiredOption(
      "input_path", &input_path, "a model with cam_from_lidar.txt (joint_adjuster's output)");
  manager.AddRequiredOption("output_path", &output_path, "folder for <station>.pcd");
  manager.Parse(argc, argv);
  RunDeskewSweepsStep(ReadStationDataset(dataset_path), input_path, output_path);
  return EXIT_SUCCESS;
}

int RunLidarRegistrator(int argc, char** argv) {
  std::string lidar_path, output_path;
  LidarRegistratorStepOptions registrator;
  CommandOptions manager;
  manager.AddRequiredOption("lidar_path", &lidar_path, "folder of station clouds (.pcd/.ply/.bin)");
  manager.AddRequiredOption("output_path", &output_path, "folder for pairs.txt, lidar_poses.txt");
  AddLidarRegistratorOptions("", &manager, &registrator);
  manager.Parse(argc, argv);
  THROW_CHECK(registrator.Check());  // before any file is read
  // A dataset's lidar/ folder: the dataset's sweep times, when it has them, time the sweeps. The
  // folder's own problems are named first.
  StationCloudFiles(lidar_path);
  const fs::path dataset_root = fs::path(lidar_path).parent_path();
  if (fs::is_regular_file(dataset_root / "rig.json")) {
    const StationDataset dataset = ReadStationDataset(dataset_root.string());
    registrator.station_times = dataset.frame_times;
    registrator.moving_platform = dataset.rig.IsMovingPlatform();
    if (!dataset.sweep_times.empty()) registrator.sweep_clock = SweepClock(dataset);
  }
  RunLidarRegistratorStep(lidar_path, output_path, registrator);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
