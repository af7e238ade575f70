#include "bridge/simulation/simulate_dataset.h"

#include "bridge/simulation/kitti_layout.h"
#include "bridge/simulation/renderer.h"
#include "bridge/simulation/scene.h"
#include "bridge/simulation/sensor_pod.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"

#include "colmap/mvs/depth_map.h"

#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

namespace colmap_lidar {
namespace sim {
namespace {

namespace fs = std::filesystem;

std::string StationName(int i) {
  std::ostringstream name;
  name << std::setw(3) << std::setfill('0') << i;
  return name.str();
}

void WriteDepthMap(const std::string& path, const cv::Mat& depth) {
  double min_depth = 0, max_depth = 0;
  cv::minMaxLoc(depth, &min_depth, &max_depth);
  colmap::mvs::DepthMap depth_map(depth.cols, depth.rows, 0.f, static_cast<float>(max_depth));
  for (int row = 0; row < depth.rows; ++row) {
    for (int col = 0; col < depth.cols; ++col) {
      depth_map.Set(row, col, depth.at<float>(row, col));
    }
  }
  depth_map.Write(path);
}

void WriteImage(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) {
    throw std::runtime_error("Cannot write image " + path);
  }
}

// The LiDAR's path during frame i's sweep: from halfway since the previous frame to halfway to the
// next (extrapolated at the ends), through the frame's own pose at tau = 0.5.
std::function<colmap::Rigid3d(double)> SweepPath(const std::vector<colmap::Rigid3d>& poses,
                                                 size_t i,
                                                 bool moving) {
  if (!moving) return [pose = poses[i]](double) { return pose; };
  const colmap::Rigid3d previous = i > 0 ? poses[i - 1] : Interpolate(poses[i], poses[i + 1], -1.0);
  const colmap::Rigid3d next =
      i + 1 < poses.size() ? poses[i + 1] : Interpolate(poses[i - 1], poses[i], 2.0);
  const colmap::Rigid3d current = poses[i];
  return [previous, current, next](double tau) {
    return tau < 0.5 ? Interpolate(previous, current, 0.5 + tau)
                     : Interpolate(current, next, tau - 0.5);
  };
}

}  // namespace

bool SimulationOptions::Check() const {
  CHECK_OPTION(!output_path.empty());
  CHECK_OPTION_GE(num_stations, 2);
  CHECK_OPTION_GT(image_scale, 0.05);
  CHECK_OPTION_LE(image_scale, 4.0);
  CHECK_OPTION_GE(lidar_points, 1000);
  CHECK_OPTION_GE(range_noise_m, 0);
  CHECK_OPTION_GE(pixel_noise, 0);
  CHECK_OPTION_GE(pixel_samples, 1);
  CHECK_OPTION_GE(guess_rotation_deg, 0);
  CHECK_OPTION_GE(guess_translation_m, 0);
  CHECK_OPTION_GT(surface_spacing_m, 1e-4);
  return true;
}

namespace {

// OUTPUT.partial with the dataset's folders; refuses an existing OUTPUT without `overwrite`.
fs::path MakePartialFolder(const SimulationOptions& options) {
  const fs::path output(options.output_path);
  if (fs::exists(output) && !options.overwrite) {
    throw std::runtime_error(output.string() + " exists; pass --overwrite 1 to replace it");
  }
  const fs::path partial = output.string() + ".partial";
  fs::remove_all(partial);
  for (const char* dir : {"images/left", "lidar", "ground_truth/depth"}) {
    fs::create_directories(partial / dir);
  }
  if (!options.mono) fs::create_directories(partial / "images/right");
  return partial;
}

// The stereo rig of the capture (the right camera kept for rendering even when the dataset is mono).
StationRig MakeStereoRigOf(const SimulationOptions& options,
                           bool drive,
                           const colmap::Rigid3d& cam_from_lidar) {
  StationRig rig = drive ? MakeDriveRig(options.image_scale) : MakeStereoRig(options.image_scale);
  if (options.write_guess) {
    rig.cam_from_lidar_guess = PerturbPose(
        cam_from_lidar, options.guess_rotation_deg, options.guess_translation_m, options.seed + 1);
  }
  rig.lidar_range_noise_m = options.range_noise_m;
  // Driving, each cloud is one revolution (from behind, counter-clockwise) while the pod moves: say
  // so, as import_kitti does, so that the pipeline de-skews them.
  if (drive && options.sweep_motion) rig.lidar_sweep = StationRig::LidarSweep();
  // KITTI's images are rectified: the right camera is not turned against the left one.
  if (options.layout == DatasetLayout::kKitti)
    rig.right_from_left.rotation = Eigen::Quaterniond::Identity();
  return rig;
}

// Station i's images (left, and right unless mono) and depth map under `partial`.
void RenderStationImages(const SimulationOptions& options,
                         const Scene& frame_scene,
                         const StationRig& stereo_rig,
                         const colmap::Rigid3d& cam_from_world,
                         size_t i,
                         const fs::path& partial) {
  const std::string name = StationName(static_cast<int>(i));
  ImageOptions image_options;
  image_options.pixel_noise = options.pixel_noise;
  image_options.vignetting = options.vignetting;
  image_options.samples_per_axis = options.pixel_samples;
  image_options.seed = options.seed * 1000 + 2 * i;
  cv::Mat depth;
  WriteImage((partial / "images/left" / (name + ".png")).string(),
             RenderImage(frame_scene, stereo_rig.left, cam_from_world, image_options, &depth));
  WriteDepthMap((partial / "ground_truth/depth" / (name + ".bin")).string(), depth);
  image_options.seed += 1;
  if (options.mono) return;
  WriteImage((partial / "images/right" / (name + ".png")).string(),
             RenderImage(frame_scene,
                         *stereo_rig.right,
                         stereo_rig.right_from_left * cam_from_world,
                         image_options,
                         nullptr));
}

// Station i's LiDAR cloud (a sweep along the path when driving) under `partial`; its size.
size_t ScanStation(const SimulationOptions& options,
                   const Scene& scene,
                   const Scene& frame_scene,
                   const std::vector<colmap::Rigid3d>& world_from_lidar,
                   size_t i,
                   const fs::path& partial) {
  LidarOptions lidar_options;
  lidar_options.num_points = options.lidar_points;
  lidar_options.range_noise_m = options.range_noise_m;
  lidar_options.mixed_edge_points = options.mixed_edge_points;
  lidar_options.seed = options.seed * 1000 + i;
  const PointCloud cloud =
      IsDrive(options.motion)
          ? ScanSweep(
                frame_scene, SweepPath(world_from_lidar, i, options.sweep_motion), lidar_options)
          : ScanLidar(scene, world_from_lidar[i], lidar_options);
  WritePointCloud((partial / "lidar" / (StationName(static_cast<int>(i)) + ".pcd")).string(),
                  cloud);
  return cloud.Size();
}

// The ground truth (station poses, cam_from_lidar, the object's surface) under `partial`; the
// surface's size.
size_t WriteGroundTruth(const SimulationOptions& options,
                        const Scene& scene,
                        const std::map<std::string, colmap::Rigid3d>& cam_from_world,
                        const colmap::Rigid3d& cam_from_lidar,
                        const fs::path& partial) {
  WriteNamedPoses((partial / "ground_truth/cam_from_world.txt").string(),
                  "True pose of each station's left camera: cam_from_world",
                  cam_from_world);
  WritePoseFile((partial / "ground_truth/cam_from_lidar.txt").string(),
                "True extrinsic: cam_from_lidar (x_cam = R x_lidar + t)",
                cam_from_lidar);
  const PointCloud surface = scene.SampleObjectSurface(options.surface_spacing_m);
  WritePointCloud((partial / "ground_truth/surface.ply").string(), surface);
  return surface.Size();
}

// OUTPUT.partial (in KITTI's layout if asked) renamed to OUTPUT.
void FinishOutput(const SimulationOptions& options, const fs::path& partial) {
  const fs::path output(options.output_path);
  if (options.layout == DatasetLayout::kKitti) {
    const fs::path kitti_partial = output.string() + ".kitti.partial";
    fs::remove_all(kitti_partial);
    WriteKittiLayout(partial.string(), kitti_partial.string());
    fs::remove_all(partial);
    fs::rename(kitti_partial, partial);
  }
  if (fs::exists(output)) fs::remove_all(output);
  fs::rename(partial, output);
}

}  // namespace

SimulationResult SimulateDataset(const SimulationOptions& options) {
  THROW_CHECK(options.Check()) << "Invalid simulation options";
  const auto start = std::chrono::steady_clock::now();
  const Scene scene = Scene::Create(options.scene);
  const Motion motion = options.motion;
  const fs::path partial = MakePartialFolder(options);
  const bool drive = IsDrive(motion);
  const colmap::Rigid3d cam_from_lidar = TrueCamFromLidar();
  // Mono: the same left images and clouds as the stereo dataset of the same seed; the right camera is
  // neither rendered nor described.
  const StationRig stereo_rig = MakeStereoRigOf(options, drive, cam_from_lidar);
  StationRig rig = stereo_rig;
  if (options.mono) rig.right.reset();
  WriteRigJson((partial / "rig.json").string(), rig);

  const std::vector<colmap::Rigid3d> stations =
      MakeStations(scene, options.num_stations, motion, options.seed);
  SimulationResult result;
  std::map<std::string, colmap::Rigid3d> cam_from_world;
  // world_from_lidar of each station (of each frame's mid-sweep instant when driving).
  std::vector<colmap::Rigid3d> world_from_lidar;
  for (const colmap::Rigid3d& station : stations) {
    world_from_lidar.push_back(colmap::Inverse(station) * cam_from_lidar);
  }
  for (size_t i = 0; i < stations.size(); ++i) {
    const std::string name = StationName(static_cast<int>(i));
    // Driving: the other cars move between frames (not during a sweep).
    const Scene frame_scene =
        drive && options.moving_cars ? scene.MovedTo(i * kDriveFramePeriod) : scene;
    cam_from_world[name] = stations[i];
    RenderStationImages(options, frame_scene, stereo_rig, stations[i], i, partial);
    const size_t num_points =
        ScanStation(options, scene, frame_scene, world_from_lidar, i, partial);
    result.num_lidar_points += num_points;
    std::cout << "simulate_dataset: station " << name << " (" << i + 1 << "/" << stations.size()
              << "): " << num_points << " LiDAR points" << std::endl;
  }
  result.num_surface_points =
      WriteGroundTruth(options, scene, cam_from_world, cam_from_lidar, partial);
  FinishOutput(options, partial);
  result.num_stations = static_cast<int>(stations.size());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

SimulationResult SimulateSmallDataset(const std::string& output_path,
                                      int num_stations,
                                      double image_scale,
                                      size_t lidar_points) {
  SimulationOptions options;
  options.output_path = output_path;
  options.num_stations = num_stations;
  options.image_scale = image_scale;
  options.lidar_points = lidar_points;
  return SimulateDataset(options);
}

}  // namespace sim
}  // namespace colmap_lidar
