#include "bridge/simulation/kitti_layout.h"

#include "bridge/simulation/sensor_pod.h"
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

// KITTI's IMU sits about 0.8 m behind and below the Velodyne; a generic small misalignment.
colmap::Rigid3d VeloFromImu() {
  return colmap::Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(
                             0.5 * M_PI / 180, Eigen::Vector3d(0.2, 0.9, -0.4).normalized())),
                         Eigen::Vector3d(-0.81, 0.32, -0.80));
}

void WriteImuCalibration(const fs::path& calib_dir, const colmap::Rigid3d& velo_from_imu) {
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r = velo_from_imu.rotation.toRotationMatrix();
  std::ostringstream file;
  file << "calib_time: 01-Jan-2026 00:00:00\nR:" << std::scientific << std::setprecision(15);
  for (int k = 0; k < 9; ++k) file << " " << r.data()[k];
  file << "\nT:";
  for (int k = 0; k < 3; ++k) file << " " << velo_from_imu.translation[k];
  file << "\n";
  std::ofstream((calib_dir / "calib_imu_to_velo.txt").string()) << file.str();
}

// The OXTS packet of an IMU pose in the simulator's world (x east, y north, z up): the inverse of
// the devkit's Mercator projection with the scale of the first packet's latitude, 49 deg north; the
// first packet sits at longitude 8.4 deg.
std::string OxtsPacketLine(const colmap::Rigid3d& world_from_imu, const Eigen::Vector3d& first) {
  constexpr double kRadius = 6378137.0, kLatitude0 = 49.0, kLongitude0 = 8.4;
  const double scale = std::cos(kLatitude0 * M_PI / 180);
  const double x0 = scale * kRadius * kLongitude0 * M_PI / 180;
  const double y0 = scale * kRadius * std::log(std::tan((90 + kLatitude0) * M_PI / 360));
  const Eigen::Vector3d mercator =
      world_from_imu.translation - first + Eigen::Vector3d(x0, y0, 120);
  const double longitude = mercator.x() / (scale * kRadius) * 180 / M_PI;
  const double latitude = 360 / M_PI * std::atan(std::exp(mercator.y() / (scale * kRadius))) - 90;
  const Eigen::Matrix3d r = world_from_imu.rotation.toRotationMatrix();
  const double yaw = std::atan2(r(1, 0), r(0, 0)), pitch = -std::asin(r(2, 0));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  std::ostringstream line;
  line << std::setprecision(17) << latitude << " " << longitude << " " << mercator.z() << " "
       << roll << " " << pitch << " " << yaw;
  for (int k = 6; k < 30; ++k) line << " 0";
  return line.str() + "\n";
}

std::string TimestampLine(double seconds_after_start) {
  // 2011-09-26 13:02:25 plus the offset, with nanoseconds as KITTI writes them.
  const double seconds = 25.0 + seconds_after_start;
  std::ostringstream line;
  line << "2011-09-26 13:02:" << std::setw(12) << std::setfill('0') << std::fixed
       << std::setprecision(9) << seconds << "\n";
  return line.str();
}

// oxts/data/*.txt and calib_imu_to_velo.txt from the true poses, and the frames' and sweeps'
// timestamps (a sweep runs from halfway since the previous frame to halfway to the next).
void WriteOxtsAndTimes(const std::vector<colmap::Rigid3d>& world_from_velo,
                       const fs::path& drive,
                       const fs::path& calib_dir) {
  const colmap::Rigid3d velo_from_imu = VeloFromImu();
  WriteImuCalibration(calib_dir, velo_from_imu);
  fs::create_directories(drive / "oxts" / "data");
  std::ofstream frames((drive / "image_02" / "timestamps.txt").string());
  std::ofstream starts((drive / "velodyne_points" / "timestamps_start.txt").string());
  std::ofstream ends((drive / "velodyne_points" / "timestamps_end.txt").string());
  const Eigen::Vector3d first = (world_from_velo.front() * velo_from_imu).translation;
  for (size_t i = 0; i < world_from_velo.size(); ++i) {
    std::ofstream((drive / "oxts" / "data" / (FrameName(i) + ".txt")).string())
        << OxtsPacketLine(world_from_velo[i] * velo_from_imu, first);
    const double time = kDriveFramePeriod * static_cast<double>(i);
    frames << TimestampLine(time);
    starts << TimestampLine(time - 0.5 * kDriveFramePeriod);
    ends << TimestampLine(time + 0.5 * kDriveFramePeriod);
  }
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
  const colmap::Rigid3d cam_from_lidar =
      ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  std::vector<colmap::Rigid3d> world_from_velo;
  for (const auto& [frame, pose] : cam_from_world) {
    world_from_velo.push_back(colmap::Inverse(pose) * cam_from_lidar);
  }
  WriteOxtsAndTimes(world_from_velo, drive, root / "calibration");
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
