#include "bridge/initialization/stereo_lidar_alignment.h"

#include "colmap_ext/dense_workspace.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/rigid3_isometry.h"
#include "colmap_ext/stereo_depth_files.h"
#include "lidar/cloud_io.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// True when the depth at (row, col) continues smoothly into its four neighbours.
bool AwayFromDepthEdge(const cv::Mat& depth, int row, int col, double max_change) {
  const float d = depth.at<float>(row, col);
  const int offsets[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
  for (const auto& offset : offsets) {
    const int r = row + offset[0], c = col + offset[1];
    if (r < 0 || c < 0 || r >= depth.rows || c >= depth.cols) return false;
    const float neighbour = depth.at<float>(r, c);
    if (!(neighbour > 0) || std::abs(neighbour - d) > max_change * d) return false;
  }
  return true;
}

// One station's depth map, back-projected through the left camera, with each depth's sigma.
CameraDepthPoints BackProjectDepthMap(const cv::Mat& depth,
                                      const colmap::Camera& camera,
                                      double focal_times_baseline,
                                      const StereoLidarAlignmentOptions& options) {
  CameraDepthPoints points;
  const int stride = std::max(
      options.pixel_stride,
      static_cast<int>(
          std::ceil(std::sqrt(double(depth.rows) * depth.cols / options.max_pixels_per_station))));
  for (int row = 0; row < depth.rows; row += stride) {
    for (int col = 0; col < depth.cols; col += stride) {
      const double d = depth.at<float>(row, col);
      if (!(d >= options.min_depth_m && d <= options.max_depth_m) ||
          !AwayFromDepthEdge(depth, row, col, options.max_neighbour_depth_change)) {
        continue;
      }
      // Pixel centres at +0.5, as COLMAP's image coordinates.
      const Eigen::Vector2d xy = camera.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5));
      points.point_in_cam.push_back(d * xy.homogeneous());
      points.sigma_along_ray_m.push_back(d * d / focal_times_baseline * options.sigma_disparity_px *
                                         xy.homogeneous().norm());
    }
  }
  return points;
}

std::unique_ptr<StationCloud> PrepareCloud(const std::string& path, double voxel_size_m) {
  StationCloudOptions cloud_options;
  cloud_options.voxel_size = voxel_size_m;
  cloud_options.compute_features = false;
  return PrepareStationCloud(ReadStationCloud(path), cloud_options);
}

std::string Describe(const StereoLidarAlignment& alignment) {
  std::ostringstream text;
  const ExtrinsicAlignmentResult& r = alignment.result;
  text.precision(3);
  text << r.num_associations << " of " << r.num_points << " stereo points on the LiDAR planes of "
       << alignment.num_stations << " stations, RMS " << 1000 * r.rms_m
       << " mm; moved the start by " << alignment.rotation_change_deg << " deg, "
       << 1000 * alignment.translation_change_m << " mm; " << r.num_weak_directions
       << " direction(s) the scenes do not fix held at the start";
  return text.str();
}

}  // namespace

bool StereoLidarAlignmentOptions::Check() const {
  CHECK_OPTION_GE(pixel_stride, 1);
  CHECK_OPTION_GE(max_pixels_per_station, 100);
  CHECK_OPTION_GT(min_depth_m, 0);
  CHECK_OPTION_GT(max_depth_m, min_depth_m);
  CHECK_OPTION_GT(sigma_disparity_px, 0);
  CHECK_OPTION_GT(max_neighbour_depth_change, 0);
  CHECK_OPTION_GE(min_associations, 6);
  CHECK_OPTION_GT(voxel_size_m, 0);
  return alignment.Check();
}

StereoLidarAlignment AlignStereoWithLidar(const StationDataset& dataset,
                                          const std::string& depth_path,
                                          const colmap::Rigid3d& initial_cam_from_lidar,
                                          const StereoLidarAlignmentOptions& options) {
  THROW_CHECK(options.Check());
  const StereoDepthInfo info = ReadStereoDepthInfo(depth_path);
  const double focal_times_baseline = info.rectified_focal_px * info.baseline_m;
  std::vector<CameraDepthPoints> points;
  std::vector<std::unique_ptr<StationCloud>> clouds;
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    const std::string map_path = StereoDepthMapPath(depth_path, dataset.stations[i]);
    if (!fs::is_regular_file(map_path)) continue;  // stereo_depth found no pair for it
    const cv::Mat depth = ReadColmapDepthMap(map_path);
    if (depth.cols != static_cast<int>(dataset.rig.left.width) ||
        depth.rows != static_cast<int>(dataset.rig.left.height)) {
      throw std::runtime_error("the depth map " + map_path + " is not the left camera's size");
    }
    points.push_back(BackProjectDepthMap(depth, dataset.rig.left, focal_times_baseline, options));
    clouds.push_back(PrepareCloud(dataset.cloud_paths[i], options.voxel_size_m));
    if (points.size() % 10 == 0 || i + 1 == dataset.stations.size()) {
      std::cout << "  stereo-LiDAR alignment: " << points.size() << " stations read" << std::endl;
    }
  }
  StereoLidarAlignment alignment;
  alignment.cam_from_lidar = initial_cam_from_lidar;
  alignment.num_stations = static_cast<int>(points.size());
  std::vector<const StationCloud*> cloud_pointers;
  for (const auto& cloud : clouds) cloud_pointers.push_back(cloud.get());
  alignment.result = AlignCameraPointsWithLidar(
      points, cloud_pointers, ToIsometry(initial_cam_from_lidar), options.alignment);
  const colmap::Rigid3d aligned = ToRigid3d(alignment.result.cam_from_lidar);
  alignment.rotation_change_deg =
      aligned.rotation.angularDistance(initial_cam_from_lidar.rotation) * 180 / M_PI;
  alignment.translation_change_m =
      (aligned.translation - initial_cam_from_lidar.translation).norm();
  if (alignment.result.num_associations < static_cast<size_t>(options.min_associations)) {
    alignment.message = "not used: only " + std::to_string(alignment.result.num_associations) +
                        " stereo points on LiDAR planes (at least " +
                        std::to_string(options.min_associations) + " needed)";
    return alignment;
  }
  alignment.used = true;
  alignment.cam_from_lidar = aligned;
  alignment.message = Describe(alignment);
  return alignment;
}

}  // namespace colmap_lidar
