#include "tests/simulator/kitti_layout.h"

#include "colmap_ext/kitti_calibration.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace sim {
namespace {

namespace fs = std::filesystem;

std::string FrameName(size_t index) {
  std::ostringstream name;
  name << std::setw(10) << std::setfill('0') << index;
  return name.str();
}

void WriteKittiBin(const std::string& path, const PointCloud& cloud) {
  std::ofstream file(path, std::ios::binary);
  for (size_t i = 0; i < cloud.Size(); ++i) {
    const float record[4] = {static_cast<float>(cloud.points[i].x()),
                             static_cast<float>(cloud.points[i].y()),
                             static_cast<float>(cloud.points[i].z()),
                             cloud.HasIntensities() ? cloud.intensities[i] : 0.f};
    file.write(reinterpret_cast<const char*>(record), sizeof(record));
  }
  if (!file) throw std::runtime_error("cannot write " + path);
}

// P_rect = K [I | offset].
Eigen::Matrix<double, 3, 4> ProjectionMatrix(const colmap::Camera& camera,
                                             const Eigen::Vector3d& offset) {
  Eigen::Matrix3d k = camera.CalibrationMatrix();
  Eigen::Matrix<double, 3, 4> p;
  p << k, k * offset;
  return p;
}

KittiCalibrationFiles CalibrationOf(const StationDataset& dataset) {
  const StationRig& rig = dataset.rig;
  const colmap::Rigid3d cam_from_lidar =
      ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  // Camera 2 sits 6 cm left of camera 0 in KITTI (P_rect_02[:,3] / fx ~ 0.06 m).
  const Eigen::Vector3d offset_2(0.0599, -0.0003, 0.0027);
  const Eigen::Vector3d baseline =
      rig.IsStereo() ? rig.right_from_left.translation : Eigen::Vector3d(-0.54, 0, 0);
  if (rig.IsStereo() &&
      rig.right_from_left.rotation.angularDistance(Eigen::Quaterniond::Identity()) > 1e-12) {
    throw std::invalid_argument(
        "KITTI's layout needs a rectified pair (right_from_left rotation "
        "identity)");
  }
  KittiCalibrationFiles files;
  files.width = static_cast<int>(rig.left.width);
  files.height = static_cast<int>(rig.left.height);
  files.p_rect = {ProjectionMatrix(rig.left, Eigen::Vector3d::Zero()),
                  ProjectionMatrix(rig.left, baseline),
                  ProjectionMatrix(rig.left, offset_2),
                  ProjectionMatrix(rig.left, offset_2 + baseline)};
  files.r_rect_00 =
      Eigen::AngleAxisd(0.4 * M_PI / 180, Eigen::Vector3d(0.3, -0.8, 0.5).normalized())
          .toRotationMatrix();
  const colmap::Rigid3d cam2_from_rect0(Eigen::Quaterniond::Identity(), offset_2);
  const colmap::Rigid3d rect0_from_cam0(Eigen::Quaterniond(files.r_rect_00),
                                        Eigen::Vector3d::Zero());
  files.cam0_from_velo = colmap::Inverse(cam2_from_rect0 * rect0_from_cam0) * cam_from_lidar;
  return files;
}

}  // namespace

void WriteKittiLayout(const std::string& dataset_path, const std::string& kitti_root) {
  const StationDataset dataset = ReadStationDataset(dataset_path);
  const fs::path root(kitti_root);
  const fs::path drive = root / "drive";
  fs::create_directories(drive / "image_02" / "data");
  fs::create_directories(drive / "velodyne_points" / "data");
  if (dataset.rig.IsStereo()) fs::create_directories(drive / "image_03" / "data");
  fs::create_directories(root / "calibration");
  WriteKittiCalibration((root / "calibration").string(), CalibrationOf(dataset));
  std::map<std::string, colmap::Rigid3d> cam_from_world;
  const auto truth = ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt"));
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    const std::string frame = FrameName(i);
    fs::copy_file(dataset.LeftImagePath(i), drive / "image_02" / "data" / (frame + ".png"));
    if (dataset.rig.IsStereo()) {
      fs::copy_file(dataset.RightImagePath(i), drive / "image_03" / "data" / (frame + ".png"));
    }
    WriteKittiBin((drive / "velodyne_points" / "data" / (frame + ".bin")).string(),
                  ReadPointCloud(dataset.cloud_paths[i]));
    cam_from_world[frame] = truth.at(dataset.stations[i]);
  }
  fs::create_directories(root / "ground_truth");
  WriteNamedPoses((root / "ground_truth" / "cam_from_world.txt").string(),
                  "True pose of each frame's camera 2: cam_from_world",
                  cam_from_world);
  fs::copy_file(dataset.GroundTruthPath("cam_from_lidar.txt"),
                root / "ground_truth" / "cam_from_lidar.txt");
  fs::copy_file(dataset.GroundTruthPath("surface.ply"), root / "ground_truth" / "surface.ply");
}

}  // namespace sim
}  // namespace colmap_lidar
