#include "bridge/dense/densifier.h"

#include "colmap_ext/camera_undistortion.h"
#include "colmap_ext/dense_workspace.h"
#include "colmap_ext/elapsed.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/stereo_depth_files.h"
#include "lidar/cloud_io.h"
#include "lidar/pinhole_depth_image.h"
#include "lidar/util/parallel_for_each.h"
#include "lidar/voxel_accumulator.h"

#include "colmap/image/undistortion.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

struct StationView {
  size_t station = 0;  // index into the dataset
  colmap::image_t image_id = colmap::kInvalidImageId;
  std::string image_name;
};

PinholeIntrinsics IntrinsicsOf(const colmap::Camera& camera) {
  PinholeIntrinsics intrinsics;
  intrinsics.width = static_cast<int>(camera.width);
  intrinsics.height = static_cast<int>(camera.height);
  intrinsics.fx = camera.FocalLengthX();
  intrinsics.fy = camera.FocalLengthY();
  intrinsics.cx = camera.PrincipalPointX();
  intrinsics.cy = camera.PrincipalPointY();
  return intrinsics;
}

// The registered images that are stations of the dataset, in station order.
std::vector<StationView> StationViews(const colmap::Reconstruction& reconstruction,
                                      const StationDataset& dataset) {
  // By the stem of the image name: "left/000.png" or a user's "000.jpg" (image_name_format).
  std::map<std::string, colmap::image_t> by_station;
  for (const colmap::image_t image_id : reconstruction.RegImageIds()) {
    by_station[std::filesystem::path(reconstruction.Image(image_id).Name()).stem().string()] =
        image_id;
  }
  std::vector<StationView> views;
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    const auto found = by_station.find(dataset.stations[i]);
    if (found == by_station.end()) {
      std::cout << "densifier: station " << dataset.stations[i]
                << " is not registered in the model; skipped" << std::endl;
      continue;
    }
    views.push_back({i, found->second, reconstruction.Image(found->second).Name()});
  }
  if (views.empty()) {
    throw std::runtime_error(
        "densifier: no registered image of the model is a station of the "
        "dataset (images must be named like " +
        dataset.LeftImageName(0) + ")");
  }
  return views;
}

// The views that see most of this view's depth map: a coarse grid of its points is projected into
// every other view; the views where most land inside the image, in front of the camera, are kept (at
// most `max_views`, each seeing at least 5 % of the grid).
std::vector<size_t> OverlappingViews(const colmap::Reconstruction& reconstruction,
                                     const std::vector<StationView>& views,
                                     size_t view_index,
                                     const cv::Mat& depth,
                                     int max_views) {
  const colmap::Image& image = reconstruction.Image(views[view_index].image_id);
  const PinholeIntrinsics intrinsics = IntrinsicsOf(reconstruction.Camera(image.CameraId()));
  const colmap::Rigid3d world_from_cam = colmap::Inverse(image.CamFromWorld());
  std::vector<Eigen::Vector3d> grid;
  const int step = std::max(1, std::min(depth.cols, depth.rows) / 32);
  for (int row = step / 2; row < depth.rows; row += step) {
    for (int col = step / 2; col < depth.cols; col += step) {
      const float z = depth.at<float>(row, col);
      if (z > 0) grid.push_back(world_from_cam * (intrinsics.PixelRay(col, row) * double(z)));
    }
  }
  std::vector<std::pair<size_t, size_t>> ranked;  // (-count, view)
  for (size_t k = 0; k < views.size(); ++k) {
    if (k == view_index) continue;
    const colmap::Image& other = reconstruction.Image(views[k].image_id);
    const PinholeIntrinsics other_intrinsics =
        IntrinsicsOf(reconstruction.Camera(other.CameraId()));
    size_t count = 0;
    for (const Eigen::Vector3d& point : grid) {
      Eigen::Vector2d xy;
      count += other_intrinsics.Project(other.CamFromWorld() * point, &xy) &&
               other_intrinsics.Contains(xy);
    }
    if (count * 20 >= grid.size() && count > 0) {
      ranked.emplace_back(grid.size() - count, k);
    }
  }
  std::sort(ranked.begin(), ranked.end());
  std::vector<size_t> neighbors;
  for (size_t r = 0; r < ranked.size() && r < size_t(max_views); ++r) {
    neighbors.push_back(ranked[r].second);
  }
  return neighbors;
}

cv::Mat NormalsToMat(const NormalImage& normals) {
  cv::Mat mat(normals.height, normals.width, CV_32FC3);
  for (int row = 0; row < normals.height; ++row) {
    for (int col = 0; col < normals.width; ++col) {
      const Eigen::Vector3f& n = normals.At(row, col);
      mat.at<cv::Vec3f>(row, col) = cv::Vec3f(n.x(), n.y(), n.z());
    }
  }
  return mat;
}

cv::Mat SourcePreview(const std::vector<DepthSource>& source, int width, int height) {
  cv::Mat preview(height, width, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      cv::Vec3b& bgr = preview.at<cv::Vec3b>(row, col);
      switch (source[size_t(row) * width + col]) {
        case DepthSource::kStereo:
          bgr = cv::Vec3b(220, 120, 40);
          break;
        case DepthSource::kLidar:
          bgr = cv::Vec3b(60, 200, 60);
          break;
        case DepthSource::kRemoved:
          bgr = cv::Vec3b(40, 40, 230);
          break;
        case DepthSource::kNone:
          break;
      }
    }
  }
  return preview;
}

// The station's stereo depth map in the original camera's grid; without image depth (`depth_path`
// empty: a monocular rig) all zeros, so that fold 2 alone fills every pixel it can from the LiDAR.
cv::Mat ReadImageDepth(const std::string& depth_path,
                       const std::string& station,
                       const colmap::Camera& original_camera) {
  const int width = static_cast<int>(original_camera.width);
  const int height = static_cast<int>(original_camera.height);
  if (depth_path.empty()) return cv::Mat::zeros(height, width, CV_32F);
  const std::string stereo_path = StereoDepthMapPath(depth_path, station);
  cv::Mat stereo = ReadColmapDepthMap(stereo_path);
  if (stereo.cols != width || stereo.rows != height) {
    throw std::runtime_error("station " + station + ": the depth map " + stereo_path + " is " +
                             std::to_string(stereo.cols) + "x" + std::to_string(stereo.rows) +
                             " but the camera is " + std::to_string(width) + "x" +
                             std::to_string(height));
  }
  return stereo;
}

// The points of `cloud` (LiDAR frame) in the camera frame that project into the image (with a
// margin of 5 % of its width) within the depth range.
std::vector<Eigen::Vector3d> LidarPointsInView(const PointCloud& cloud,
                                               const colmap::Rigid3d& cam_from_lidar,
                                               const PinholeIntrinsics& intrinsics,
                                               const DensifierOptions& options) {
  std::vector<Eigen::Vector3d> in_view;
  const double margin = 0.05 * intrinsics.width;
  for (const Eigen::Vector3d& point_in_lidar : cloud.points) {
    const Eigen::Vector3d point_in_cam = cam_from_lidar * point_in_lidar;
    Eigen::Vector2d xy;
    if (point_in_cam.z() < options.min_depth_m || point_in_cam.z() > options.max_depth_m ||
        !intrinsics.Project(point_in_cam, &xy)) {
      continue;
    }
    if (xy.x() < -margin || xy.y() < -margin || xy.x() > intrinsics.width + margin ||
        xy.y() > intrinsics.height + margin) {
      continue;
    }
    in_view.push_back(point_in_cam);
  }
  return in_view;
}

// Folds 1 and 2 (lidar/lidar_depth_refinement.h) on one station's stereo depth with its LiDAR
// points in view; without refine_with_lidar the stereo depth as it is.
RefinedDepth RefineStationDepth(const Eigen::Map<const DepthImage>& stereo_depth,
                                const std::vector<Eigen::Vector3d>& in_view,
                                const PinholeIntrinsics& intrinsics,
                                const StationDataset& dataset,
                                bool has_image_depth,
                                const DensifierOptions& options) {
  RefinedDepth refined;
  if (options.refine_with_lidar) {
    LidarSurfaceOptions surface_options = options.surface;
    // The samples of a sparse sweep grow their neighbourhoods instead of being dropped where the
    // LiDAR is the only depth (a monocular rig) and on a moving platform (rig.json's clouds are
    // sweeps), whose stereo is decimetres off at 10-30 m. Tripod stations, whose dense clouds cover
    // the stereo, keep the strict neighbourhoods.
    surface_options.grow_sparse_neighbourhoods |=
        !has_image_depth || dataset.rig.IsMovingPlatform();
    const LidarSurface surface = BuildLidarSurface(in_view, surface_options);
    return RefineDepthWithLidar(stereo_depth, surface, intrinsics, options.refinement);
  }
  refined.depth = stereo_depth;
  refined.normals = NormalsFromDepth(refined.depth, intrinsics);
  refined.source.assign(refined.depth.size(), DepthSource::kNone);
  for (Eigen::Index k = 0; k < refined.depth.size(); ++k) {
    if (refined.depth.data()[k] > 0) {
      refined.source[k] = DepthSource::kStereo;
      ++refined.stats.stereo_pixels;
      ++refined.stats.stereo_without_lidar;
    }
  }
  return refined;
}

// One station's refined depth and normal maps, its (undistorted) image and the preview of where
// each pixel's depth came from, into the workspace.
void WriteStationMaps(const StationView& view,
                      const StationDataset& dataset,
                      const DenseWorkspace& workspace,
                      const CameraUndistorter* undistorter,
                      RefinedDepth* refined) {
  const std::string& station = dataset.stations[view.station];
  const int height = static_cast<int>(refined->depth.rows());
  const int width = static_cast<int>(refined->depth.cols());
  const cv::Mat depth_mat(height, width, CV_32F, refined->depth.data());
  workspace.WriteDepthMap(view.image_name, depth_mat);
  workspace.WriteNormalMap(view.image_name, NormalsToMat(refined->normals));
  if (undistorter) {
    const std::string image_path = dataset.LeftImagePath(view.station);
    const cv::Mat distorted = cv::imread(image_path, cv::IMREAD_COLOR);
    if (distorted.empty()) {
      throw std::runtime_error("station " + station + ": cannot read " + image_path);
    }
    workspace.WriteImage(view.image_name, undistorter->UndistortImage(distorted));
  } else {
    workspace.CopyImage(view.image_name, dataset.LeftImagePath(view.station));
  }
  const fs::path preview_dir = fs::path(workspace.Root()) / "stereo" / "previews";
  fs::create_directories(preview_dir);
  cv::imwrite((preview_dir / (station + ".png")).string(),
              SourcePreview(refined->source, width, height));
}

// Fold 1 and 2 for one station; writes its maps, image and preview into the workspace and returns
// its LiDAR cloud in the world frame (for the LiDAR map) in `points_in_world`.
// What every station's refinement reads: the pinhole model, the calibration, the dataset with its
// stereo depth (`depth_path`, empty: none) and the dense workspace written into.
struct DensifyContext {
  const colmap::Reconstruction& reconstruction;
  const colmap::Rigid3d& cam_from_lidar;
  const StationDataset& dataset;
  const std::string& depth_path;
  const DenseWorkspace& workspace;
  const DensifierOptions& options;
};

StationDensification RefineStation(const DensifyContext& context,
                                   const StationView& view,
                                   const colmap::Camera& original_camera,
                                   const CameraUndistorter* undistorter,
                                   std::vector<Eigen::Vector3d>* points_in_world) {
  const colmap::Reconstruction& reconstruction = context.reconstruction;
  const colmap::Rigid3d& cam_from_lidar = context.cam_from_lidar;
  const StationDataset& dataset = context.dataset;
  const std::string& depth_path = context.depth_path;
  const DensifierOptions& options = context.options;
  const std::string& station = dataset.stations[view.station];
  StationDensification result;
  result.station = station;
  const colmap::Image& image = reconstruction.Image(view.image_id);
  const colmap::Camera& camera = reconstruction.Camera(image.CameraId());
  const PinholeIntrinsics intrinsics = IntrinsicsOf(camera);

  cv::Mat stereo = ReadImageDepth(depth_path, station, original_camera);
  if (undistorter) stereo = undistorter->UndistortDepthMap(stereo);
  const Eigen::Map<const DepthImage> stereo_depth(stereo.ptr<float>(), stereo.rows, stereo.cols);

  // The station's cloud: into the LiDAR map (world frame), and cropped to the camera's view.
  const PointCloud cloud = ReadStationCloud(dataset.cloud_paths[view.station]);
  const colmap::Rigid3d world_from_lidar = colmap::Inverse(image.CamFromWorld()) * cam_from_lidar;
  points_in_world->clear();
  points_in_world->reserve(cloud.Size());
  for (const Eigen::Vector3d& point_in_lidar : cloud.points) {
    points_in_world->push_back(world_from_lidar * point_in_lidar);
  }
  const std::vector<Eigen::Vector3d> in_view =
      LidarPointsInView(cloud, cam_from_lidar, intrinsics, options);
  result.lidar_points_in_view = in_view.size();

  RefinedDepth refined =
      RefineStationDepth(stereo_depth, in_view, intrinsics, dataset, !depth_path.empty(), options);
  result.refinement = refined.stats;

  WriteStationMaps(view, dataset, context.workspace, undistorter, &refined);
  return result;
}

// A neighbouring view's depth map with its camera.
struct OtherView {
  cv::Mat depth;
  PinholeIntrinsics intrinsics;
  colmap::Rigid3d cam_from_world;
};

// The refined depth maps of the views that overlap view `view_index` most (at most
// max_neighbor_views).
std::vector<OtherView> OtherDepthMaps(const colmap::Reconstruction& reconstruction,
                                      const std::vector<StationView>& views,
                                      size_t view_index,
                                      const cv::Mat& depth,
                                      const DenseWorkspace& workspace,
                                      const DensifierOptions& options) {
  std::vector<OtherView> others;
  for (size_t k :
       OverlappingViews(reconstruction, views, view_index, depth, options.max_neighbor_views)) {
    const colmap::Image& other = reconstruction.Image(views[k].image_id);
    others.push_back({workspace.ReadDepthMap(views[k].image_name),
                      IntrinsicsOf(reconstruction.Camera(other.CameraId())),
                      other.CamFromWorld()});
  }
  return others;
}

// How many of `others` see `point_in_world` at their own depth (within the consistency tolerance).
int AgreeingViews(const std::vector<OtherView>& others,
                  const Eigen::Vector3d& point_in_world,
                  const DensifierOptions& options) {
  int agreeing = 0;
  for (const OtherView& other : others) {
    const Eigen::Vector3d point_in_other = other.cam_from_world * point_in_world;
    Eigen::Vector2d xy;
    if (!other.intrinsics.Project(point_in_other, &xy) || !other.intrinsics.Contains(xy)) {
      continue;
    }
    const float other_z = other.depth.at<float>(static_cast<int>(xy.y()), static_cast<int>(xy.x()));
    agreeing +=
        other_z > 0 && std::abs(other_z - point_in_other.z()) <=
                           options.consistency_abs_m + options.consistency_rel * point_in_other.z();
  }
  return agreeing;
}

// Back-projects one station's refined map (with colour and normals) into the fused grid.
void FuseStation(const DensifyContext& context,
                 const std::vector<StationView>& views,
                 size_t view_index,
                 StationDensification* result,
                 VoxelAccumulator* fused) {
  const colmap::Reconstruction& reconstruction = context.reconstruction;
  const DenseWorkspace& workspace = context.workspace;
  const DensifierOptions& options = context.options;
  const StationView& view = views[view_index];
  const colmap::Image& image = reconstruction.Image(view.image_id);
  const PinholeIntrinsics intrinsics = IntrinsicsOf(reconstruction.Camera(image.CameraId()));
  const cv::Mat depth = workspace.ReadDepthMap(view.image_name);
  const cv::Mat normals = workspace.ReadNormalMap(view.image_name);
  const std::string image_path = workspace.ImagePath(view.image_name);
  const cv::Mat bgr = cv::imread(image_path, cv::IMREAD_COLOR);
  if (bgr.empty() || bgr.cols != depth.cols || bgr.rows != depth.rows) {
    throw std::runtime_error("densifier: cannot read " + image_path + " at the depth map's size");
  }
  const std::vector<OtherView> others =
      options.min_consistent_views > 0
          ? OtherDepthMaps(reconstruction, views, view_index, depth, workspace, options)
          : std::vector<OtherView>();
  const colmap::Rigid3d world_from_cam = colmap::Inverse(image.CamFromWorld());
  const Eigen::Matrix3d world_from_cam_rotation = world_from_cam.rotation.toRotationMatrix();

  struct Sample {
    Eigen::Vector3d point;
    Eigen::Vector3f normal;
    Color3ub color;
  };
  std::vector<std::vector<Sample>> rows(depth.rows);
  size_t inconsistent = 0;
#pragma omp parallel for schedule(dynamic, 8) reduction(+ : inconsistent)
  for (int row = 0; row < depth.rows; ++row) {
    for (int col = 0; col < depth.cols; ++col) {
      const float z = depth.at<float>(row, col);
      if (!(z > 0)) continue;
      const Eigen::Vector3d ray = intrinsics.PixelRay(col, row);
      const Eigen::Vector3d point_in_world = world_from_cam * (ray * double(z));
      if (options.min_consistent_views > 0 &&
          AgreeingViews(others, point_in_world, options) < options.min_consistent_views) {
        ++inconsistent;
        continue;
      }
      const cv::Vec3f& n = normals.at<cv::Vec3f>(row, col);
      Eigen::Vector3d normal_in_cam(n[0], n[1], n[2]);
      if (normal_in_cam.isZero()) normal_in_cam = -ray.normalized();
      const cv::Vec3b& color = bgr.at<cv::Vec3b>(row, col);
      rows[row].push_back({point_in_world,
                           (world_from_cam_rotation * normal_in_cam).cast<float>(),
                           Color3ub(color[2], color[1], color[0])});
    }
  }
  for (const auto& samples : rows) {
    for (const Sample& sample : samples) {
      fused->Add(sample.point, sample.normal, sample.color);
      ++result->points;
    }
  }
  result->inconsistent = inconsistent;
}

// Every station's refined map back-projected into one voxel grid: the fused cloud.
PointCloud FuseStations(const DensifyContext& context,
                        const std::vector<StationView>& views,
                        DensifierSummary* summary) {
  VoxelAccumulator fused(context.options.fused_voxel_size_m);
  for (size_t k = 0; k < views.size(); ++k) {
    const auto station_start = std::chrono::steady_clock::now();
    FuseStation(context, views, k, &summary->stations[k], &fused);
    summary->stations[k].seconds += SecondsSince(station_start);
  }
  const size_t num_fused_points = fused.NumPointsAdded();
  PointCloud fused_cloud = fused.ExtractAndClear();
  summary->fused_points = fused_cloud.Size();
  std::cout << "densifier: fused " << num_fused_points << " points into " << fused_cloud.Size()
            << " voxels of " << context.options.fused_voxel_size_m * 1000 << " mm" << std::endl;
  return fused_cloud;
}

// The workspace's sparse model and the configuration files of COLMAP's dense steps.
void WriteWorkspaceModel(const DensifyContext& context, const std::vector<StationView>& views) {
  context.workspace.WriteSparse(context.reconstruction);
  std::vector<std::string> names;
  for (const StationView& view : views) names.push_back(view.image_name);
  context.workspace.WriteConfigs(names);
}

nlohmann::json StationReport(const StationDensification& station) {
  const LidarDepthRefinementStats& s = station.refinement;
  return {{"station", station.station},
          {"lidar_points_in_view", station.lidar_points_in_view},
          {"stereo_pixels", s.stereo_pixels},
          {"stereo_confirmed", s.stereo_confirmed},
          {"stereo_without_lidar", s.stereo_without_lidar},
          {"stereo_removed", s.stereo_removed},
          {"filled", s.filled},
          {"fill_refused_edge", s.fill_refused_edge},
          {"fill_refused_sparse", s.fill_refused_sparse},
          {"fill_refused_view_angle", s.fill_refused_view_angle},
          {"fill_refused_curvature", s.fill_refused_curvature},
          {"window_radius_px", s.window_radius_px},
          {"inconsistent", station.inconsistent},
          {"points", station.points},
          {"seconds", station.seconds}};
}

// The model in undistorted pinhole cameras: distorted ones are replaced by COLMAP's undistorted camera
// (and the keypoints moved), as colmap::UndistortReconstruction does but for every non-pinhole model
// (it skips models whose coefficients happen to be zero, which the workspace could not hold). The
// undistorters resample each distorted camera's maps and images.
colmap::Reconstruction PinholeModel(
    const colmap::Reconstruction& input_model,
    std::map<colmap::camera_t, std::unique_ptr<CameraUndistorter>>* undistorters) {
  colmap::Reconstruction reconstruction = input_model;
  for (const auto& [camera_id, camera] : input_model.Cameras()) {
    if (IsPinholeCamera(camera)) continue;
    reconstruction.Camera(camera_id) =
        colmap::UndistortCamera(colmap::UndistortCameraOptions(), camera);
    (*undistorters)[camera_id] =
        std::make_unique<CameraUndistorter>(camera, reconstruction.Camera(camera_id));
    std::cout << "densifier: camera " << camera_id << " (" << camera.ModelName()
              << ") is undistorted to PINHOLE " << reconstruction.Camera(camera_id).width << "x"
              << reconstruction.Camera(camera_id).height << std::endl;
  }
  if (undistorters->empty()) return reconstruction;
  for (const auto& [image_id, image] : input_model.Images()) {
    const colmap::Camera& original = input_model.Camera(image.CameraId());
    const colmap::Camera& pinhole = reconstruction.Camera(image.CameraId());
    colmap::Image& moved = reconstruction.Image(image_id);
    for (colmap::point2D_t k = 0; k < moved.NumPoints2D(); ++k) {
      moved.Point2D(k).xy = pinhole.ImgFromCam(original.CamFromImg(image.Point2D(k).xy));
    }
  }
  return reconstruction;
}

void PrintStation(size_t k, size_t num_stations, const StationDensification& station) {
  const LidarDepthRefinementStats& s = station.refinement;
  std::cout << "densifier: [" << k + 1 << "/" << num_stations << "] station " << station.station
            << ": " << s.stereo_pixels << " stereo pixels (" << s.stereo_confirmed
            << " confirmed by LiDAR, " << s.stereo_removed << " removed), " << s.filled
            << " filled from " << station.lidar_points_in_view << " LiDAR points in view ("
            << std::fixed << std::setprecision(1) << station.seconds << " s)" << std::endl;
}

nlohmann::json DensifierReport(const DensifierOptions& options,
                               const DensifierSummary& summary,
                               bool has_image_depth) {
  nlohmann::json report;
  report["image_depth"] = has_image_depth
                              ? "stereo"
                              : "none: there is no image depth (no stereo depth maps, e.g. a "
                                "monocular rig); every depth comes from the LiDAR, projected and "
                                "densified within flat layers (fold 2 alone)";
  report["refine_with_lidar"] = options.refine_with_lidar;
  report["min_consistent_views"] = options.min_consistent_views;
  report["fused_voxel_size_m"] = options.fused_voxel_size_m;
  report["fused_points"] = summary.fused_points;
  report["lidar_map_points"] = summary.lidar_map_points;
  report["seconds"] = summary.seconds;
  const LidarDepthRefinementOptions& r = options.refinement;
  report["refinement"] = {{"window_radius_px", r.window_radius_px},
                          {"max_abs_diff_m", r.max_abs_diff_m},
                          {"max_rel_diff", r.max_rel_diff},
                          {"plane_tolerance_m", r.plane_tolerance_m},
                          {"max_normal_angle_deg", r.max_normal_angle_deg},
                          {"max_fill_curvature", r.max_fill_curvature},
                          {"max_fill_view_angle_deg", r.max_fill_view_angle_deg}};
  for (const StationDensification& station : summary.stations) {
    report["stations"].push_back(StationReport(station));
  }
  return report;
}

// Joins each station's LiDAR points into the map in station order, whatever order the stations
// finish in: a voxel's mean depends on the order of its sums. A station that finishes early waits
// here until those before it have joined.
class StationOrderedMap {
 public:
  explicit StationOrderedMap(VoxelAccumulator* map) : map_(map) {}

  // Not thread-safe: the caller serialises the calls.
  void Add(int station, std::vector<Eigen::Vector3d> points) {
    waiting_[station] = std::move(points);
    for (auto next = waiting_.begin(); next != waiting_.end() && next->first == next_station_;
         next = waiting_.erase(next), ++next_station_) {
      for (const Eigen::Vector3d& point : next->second) {
        map_->Add(point, Eigen::Vector3f::Zero(), Color3ub(128, 128, 128));
      }
    }
  }

 private:
  VoxelAccumulator* map_;
  std::map<int, std::vector<Eigen::Vector3d>> waiting_;
  int next_station_ = 0;
};

}  // namespace

bool DensifierOptions::Check() const {
  CHECK_OPTION(surface.Check());
  CHECK_OPTION(refinement.Check());
  CHECK_OPTION_GT(min_depth_m, 0);
  CHECK_OPTION_GT(max_depth_m, min_depth_m);
  CHECK_OPTION_GE(min_consistent_views, 0);
  CHECK_OPTION_GE(max_neighbor_views, min_consistent_views);
  CHECK_OPTION_GE(consistency_abs_m, 0);
  CHECK_OPTION_GE(consistency_rel, 0);
  CHECK_OPTION_GT(fused_voxel_size_m, 0);
  CHECK_OPTION_GT(lidar_map_voxel_size_m, 0);
  return true;
}

DensifierSummary Densify(const colmap::Reconstruction& input_model,
                         const colmap::Rigid3d& cam_from_lidar,
                         const StationDataset& dataset,
                         const std::string& depth_path,
                         const std::string& output_path,
                         const DensifierOptions& options) {
  THROW_CHECK(options.Check());
  if (depth_path.empty() && !options.refine_with_lidar) {
    throw std::invalid_argument(
        "no stereo depth maps and refine_with_lidar off: there would be no depth at all");
  }
  const auto start = std::chrono::steady_clock::now();
  const std::vector<StationView> views = StationViews(input_model, dataset);
  std::map<colmap::camera_t, std::unique_ptr<CameraUndistorter>> undistorters;
  const colmap::Reconstruction reconstruction = PinholeModel(input_model, &undistorters);
  PartialOutputFolder partial(output_path);
  DensifierSummary summary;
  const DenseWorkspace workspace(partial.Path());
  VoxelAccumulator lidar_map(options.lidar_map_voxel_size_m);
  std::cout << "densifier: " << views.size() << " stations, "
            << (depth_path.empty()          ? "no image depth (LiDAR depth only, flat layers)"
                : options.refine_with_lidar ? "LiDAR-refined"
                                            : "stereo only")
            << std::endl;
  // Stations in parallel (each station's own loops then run on its thread alone).
  summary.stations.resize(views.size());
  std::mutex mutex;
  size_t num_done = 0;
  StationOrderedMap ordered_lidar_map(&lidar_map);
  const DensifyContext context{
      reconstruction, cam_from_lidar, dataset, depth_path, workspace, options};
  ParallelForEach(static_cast<int>(views.size()), [&](int k) {
    const auto station_start = std::chrono::steady_clock::now();
    const colmap::camera_t camera_id = input_model.Image(views[k].image_id).CameraId();
    const auto undistorter = undistorters.find(camera_id);
    std::vector<Eigen::Vector3d> points_in_world;
    StationDensification station =
        RefineStation(context,
                      views[k],
                      input_model.Camera(camera_id),
                      undistorter == undistorters.end() ? nullptr : undistorter->second.get(),
                      &points_in_world);
    std::lock_guard<std::mutex> lock(mutex);
    ordered_lidar_map.Add(k, std::move(points_in_world));
    station.seconds = SecondsSince(station_start);
    PrintStation(num_done++, views.size(), station);
    summary.stations[k] = std::move(station);
  });

  PointCloud lidar_cloud = lidar_map.ExtractAndClear();
  lidar_cloud.normals.clear();
  summary.lidar_map_points = lidar_cloud.Size();
  WritePointCloud(partial.File("lidar_map.ply"), lidar_cloud);
  lidar_cloud = PointCloud();

  WritePointCloud(partial.File("fused.ply"), FuseStations(context, views, &summary));

  WriteWorkspaceModel(context, views);
  summary.seconds = SecondsSince(start);
  WriteFileAtomically(partial.File("densifier.json"),
                      DensifierReport(options, summary, !depth_path.empty()).dump(2) + "\n");
  partial.Commit();
  return summary;
}

}  // namespace colmap_lidar
