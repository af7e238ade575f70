// Writes a complete station dataset (docs/dataset_format.md) with ground truth for a simulated capture.
#pragma once

#include "bridge/simulation/sensor_pod.h"
#include "lidar/util/named_choice.h"

#include <cstdint>
#include <string>

namespace colmap_lidar {
namespace sim {

// How the dataset is written: docs/dataset_format.md, or KITTI raw's layout and calibration files
// with a rectified right camera (bridge/simulation/kitti_layout.h).
enum class DatasetLayout { kDataset, kKitti };
inline constexpr NamedChoices<DatasetLayout, 2> kDatasetLayoutNames = {
    {{"dataset", DatasetLayout::kDataset}, {"kitti", DatasetLayout::kKitti}}};

struct SimulationOptions {
  std::string scene = "t_specimen";
  std::string output_path;
  int num_stations = 25;
  // Drives (IsDrive): frames of a car (MakeDriveRig), one ScanSweep per frame with the frame's pose
  // at mid-sweep, cars moving between frames; scene "street".
  Motion motion = Motion::kTwoAxes;
  // drive: the pod moves during each sweep (false: a frozen pod per sweep, as stop-and-go; isolates
  // de-skewing in experiments)
  bool sweep_motion = true;
  // drive: the two cars driving in the street move between frames (false: they stand still)
  bool moving_cars = true;
  // 1 = 1028x752 per camera, 4 = the 4112x3008 of Zhen et al. 2019
  double image_scale = 1.0;
  // One camera: rig.json without "right", no images/right/ (a monocular dataset).
  bool mono = false;
  DatasetLayout layout = DatasetLayout::kDataset;
  // LiDAR rays per station
  size_t lidar_points = 1600000;
  double range_noise_m = 0.01;
  // grey levels
  double pixel_noise = 1.0;
  bool vignetting = false;
  // rays per pixel along each image axis (ImageOptions::samples_per_axis)
  int pixel_samples = 1;
  bool mixed_edge_points = false;
  // cam_from_lidar_guess = truth perturbed by this much
  double guess_rotation_deg = 3.0;
  double guess_translation_m = 0.05;
  bool write_guess = true;
  // grid of ground_truth/surface.ply
  double surface_spacing_m = 0.005;
  uint64_t seed = 0;
  bool overwrite = false;

  bool Check() const;  // CHECK_OPTION_* on every field
};

struct SimulationResult {
  int num_stations = 0;
  size_t num_lidar_points = 0;
  size_t num_surface_points = 0;
  double seconds = 0;
};

// Everything is written into OUTPUT.partial and renamed to OUTPUT at the end: an interrupted or failed
// run never leaves a dataset that looks complete. Prints a progress line per station.
SimulationResult SimulateDataset(const SimulationOptions& options);

// A small dataset of the default scene for tests: `num_stations` stations, images scaled by
// `image_scale`, `lidar_points` rays per station, every other option at its default.
SimulationResult SimulateSmallDataset(const std::string& output_path,
                                      int num_stations,
                                      double image_scale,
                                      size_t lidar_points);

}  // namespace sim
}  // namespace colmap_lidar
