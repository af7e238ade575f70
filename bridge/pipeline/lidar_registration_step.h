// The LiDAR registrator as a library call: the station clouds of a folder registered into the
// LiDAR pose graph A_l (pairwise BSC + RANSAC + ICP for tripod stations, frame-to-map odometry for
// the sweeps of a moving platform), with the sweeps de-skewed and moving points left out where asked;
// writes OUTPUT/ (pairs.txt, lidar_poses.txt, summary.txt, deskewed/, static/). And deskew_sweeps:
// a dataset's raw sweeps de-skewed with the trajectory of a model.
#pragma once

#include "colmap_ext/station_dataset.h"
#include "lidar/lidar_odometry.h"
#include "lidar/lidar_pose_graph.h"
#include "lidar/moving_points.h"
#include "lidar/revisit_closure.h"
#include "lidar/station_cloud.h"
#include "lidar/sweep_deskew.h"
#include "lidar/util/named_choice.h"

#include <filesystem>
#include <string>
#include <vector>

namespace colmap_lidar {

// lidar_registrator: BSC + RANSAC + ICP over station pairs, the LiDAR pose graph A_l.
// lidar_registrator's --method (see LidarRegistratorStepOptions::method).
enum class RegistrationMethod { kAuto, kPairwise, kOdometry };
inline constexpr NamedChoices<RegistrationMethod, 3> kRegistrationMethodNames = {
    {{"auto", RegistrationMethod::kAuto},
     {"pairwise", RegistrationMethod::kPairwise},
     {"odometry", RegistrationMethod::kOdometry}}};
// lidar_registrator's --remove_moving_points (see LidarRegistratorStepOptions).
enum class MovingPointRemoval { kAuto, kOn, kOff };
inline constexpr NamedChoices<MovingPointRemoval, 5> kMovingPointRemovalNames = {
    {{"auto", MovingPointRemoval::kAuto},
     {"on", MovingPointRemoval::kOn},
     {"off", MovingPointRemoval::kOff},
     {"1", MovingPointRemoval::kOn},
     {"0", MovingPointRemoval::kOff}}};

struct LidarRegistratorStepOptions {
  StationCloudOptions cloud;
  LidarGraphOptions graph;
  // Parsed as int (the OptionManager has no size_t); GraphOptions() gives `graph` with them.
  int max_neighbors = 0;
  int sequential = 0;
  int bridge_neighbors = 4;
  // Sweeps of a moving platform (frames in name order): register, de-skew every sweep with the motion
  // to its neighbour (lidar/sweep_deskew.h), write OUTPUT/deskewed/<station>.pcd and register again;
  // the later steps of `pipeline` use the de-skewed clouds.
  bool deskew_sweeps = false;
  SweepTimingOptions sweep_timing;
  // The station clouds of a folder (.pcd, .ply, .bin), sorted by name; throws naming the folder
  // unless there are at least two.
  std::vector<std::filesystem::path> StationCloudFiles(const std::string& lidar_path);

  // Each station's sweep middle in sweep durations (lidar/sweep_deskew.h SweepClockFromTimes of
  // the dataset's sweep_times.txt); empty: frame indices from the station names.
  std::vector<double> sweep_clock;
  // Each station's frame time [s] (the dataset's timestamps.txt) for the TUM export; empty: none.
  std::vector<double> station_times;
  // auto | pairwise | odometry. Pairwise: BSC + RANSAC + ICP over station pairs (tripod stations,
  // any prior). Odometry: sequential frame-to-map ICP (lidar/lidar_odometry.h) for the sweeps of a
  // moving platform. Auto: odometry for sweeps (deskew_sweeps or moving_platform), else pairwise.
  RegistrationMethod method = RegistrationMethod::kAuto;
  bool moving_platform = false;  // the dataset's rig.json says so
  LidarOdometryOptions odometry;
  // Odometry: revisit edges between keyframes near in space, far along the path, registered by BSC
  // + RANSAC + ICP and accepted within the odometry's drift (lidar/revisit_closure.h); `revisit`'s
  // cloud and pair options are this step's `cloud` and `graph.pair`.
  bool revisits = true;
  RevisitOptions revisit;
  // Odometry: k > 0 refines the trajectory by ICP between each de-skewed sweep and its next
  // `refine_neighbors` sweeps at `cloud`'s resolution (lidar/trajectory_refinement.h), then
  // de-skews the sweeps again with the refined motion.
  int refine_neighbors = 2;
  // After registration, flag the points of moving objects by free space (lidar/moving_points.h) and
  // write each cloud without them to OUTPUT/static/<station>.pcd (and all flagged points, in the
  // first station's frame, to OUTPUT/moving_points.ply); the later steps of `pipeline` use them.
  // Auto: for sweeps of a moving platform (with deskew_sweeps).
  MovingPointRemoval remove_moving_points = MovingPointRemoval::kAuto;
  MovingPointOptions moving;

  bool Check() const;
  // `graph` with max_neighbors, sequential and bridge_neighbors.
  LidarGraphOptions GraphOptions() const;
  // Whether moving points are removed (remove_moving_points; auto decided by deskew_sweeps).
  bool RemovesMovingPoints() const;
};
// The station clouds of a folder (.pcd, .ply, .bin), sorted by name; throws naming the folder
// unless there are at least two.
std::vector<std::filesystem::path> StationCloudFiles(const std::string& lidar_path);

// Each station's sweep middle in sweep durations: from the dataset's sweep_times.txt, else the
// frame index of numeric station names (else the position in name order).
std::vector<double> SweepClock(const StationDataset& dataset);
void RunLidarRegistratorStep(const std::string& lidar_path,
                             const std::string& output_path,
                             LidarRegistratorStepOptions options);

// The dataset's raw sweeps (rig.json with lidar.sweep) de-skewed with the trajectory of the model at
// `model_path` (its images and cam_from_lidar.txt) into OUTPUT/<station>.pcd.
void RunDeskewSweepsStep(const StationDataset& dataset,
                         const std::string& model_path,
                         const std::string& output_path);

}  // namespace colmap_lidar
