// KITTI raw's layout (Geiger, Lenz, Stiller, Urtasun, IJRR 2013): DRIVE/image_0X/data/%010d.png,
// DRIVE/velodyne_points/data/%010d.bin, the day's calibration files; optionally OXTS packets
// (DRIVE/oxts/data/%010d.txt) and timestamps per frame.
#include "colmap_ext/kitti_oxts.h"
#include "colmap_ext/kitti_source.h"

#include <algorithm>
#include <filesystem>

namespace colmap_lidar {

namespace fs = std::filesystem;

namespace {

// The left camera's reference poses from the OXTS packets: world_from_velo = world_from_imu
// velo_from_imu^-1 (world: the first selected frame's IMU), cam_from_world = cam_from_velo
// world_from_velo^-1.
std::vector<colmap::Rigid3d> OxtsCamFromWorld(const fs::path& oxts_folder,
                                              const std::vector<std::string>& frames,
                                              const KittiImportOptions& options,
                                              const KittiCamera& left) {
  std::vector<OxtsPacket> packets;
  for (const std::string& frame : frames) {
    packets.push_back(ReadOxtsPacket((oxts_folder / (frame + ".txt")).string()));
  }
  const colmap::Rigid3d imu_from_velo = colmap::Inverse(ReadKittiVeloFromImu(options.calib_path));
  std::vector<colmap::Rigid3d> cam_from_world;
  for (const colmap::Rigid3d& world_from_imu : WorldFromImuFromOxts(packets)) {
    cam_from_world.push_back(left.cam_from_velo * colmap::Inverse(world_from_imu * imu_from_velo));
  }
  return cam_from_world;
}

// The values of a per-frame timestamp file at the selected frame indices.
std::vector<double> TimesAt(const fs::path& path, const std::vector<int>& indices) {
  const int last = *std::max_element(indices.begin(), indices.end());
  const std::vector<double> all = ReadKittiTimestamps(path.string(), static_cast<size_t>(last) + 1);
  std::vector<double> times;
  for (const int index : indices) times.push_back(all[index]);
  return times;
}

void ReadRawTimes(const fs::path& drive,
                  const std::vector<int>& indices,
                  int camera,
                  KittiSource* source) {
  const fs::path frame_times = drive / ("image_0" + std::to_string(camera)) / "timestamps.txt";
  if (fs::is_regular_file(frame_times)) {
    source->frame_times = TimesAt(frame_times, indices);
  } else {
    source->notes.push_back(frame_times.string() + " is absent: no frame times");
  }
  const fs::path start = drive / "velodyne_points" / "timestamps_start.txt";
  const fs::path end = drive / "velodyne_points" / "timestamps_end.txt";
  if (!fs::is_regular_file(start) || !fs::is_regular_file(end)) {
    source->notes.push_back(
        "velodyne_points/timestamps_start.txt or timestamps_end.txt is absent: sweeps are "
        "de-skewed with one revolution per frame");
    return;
  }
  const std::vector<double> starts = TimesAt(start, indices), ends = TimesAt(end, indices);
  for (size_t k = 0; k < starts.size(); ++k) {
    if (!(ends[k] > starts[k])) {
      throw std::runtime_error(end.string() + ": the sweep of frame " + source->frames[k] +
                               " ends before it starts (" + start.string() + ")");
    }
    source->sweep_times.emplace_back(starts[k], ends[k]);
  }
}

}  // namespace

KittiSource ReadKittiRawDrive(const KittiImportOptions& options) {
  const fs::path drive(options.kitti_path);
  const auto image_folder = [&](int camera) {
    return (drive / ("image_0" + std::to_string(camera)) / "data").string();
  };
  KittiSource source;
  source.left = ReadKittiCamera(options.calib_path, options.camera);
  std::vector<int> indices;
  for (const auto& [frame, index] : SelectKittiFrames(image_folder(options.camera), options)) {
    source.frames.push_back(frame);
    indices.push_back(index);
    source.left_images.push_back(
        (fs::path(image_folder(options.camera)) / (frame + ".png")).string());
    source.clouds.push_back((drive / "velodyne_points" / "data" / (frame + ".bin")).string());
  }
  source.right_images = KittiRightImages(image_folder(options.camera + 1), source.frames, options);
  if (!source.right_images.empty()) {
    source.right = ReadKittiCamera(options.calib_path, options.camera + 1);
  }
  ReadRawTimes(drive, indices, options.camera, &source);
  const fs::path oxts = drive / "oxts" / "data";
  if (fs::is_directory(oxts)) {
    source.reference_cam_from_world = OxtsCamFromWorld(oxts, source.frames, options, source.left);
    source.reference_description = "KITTI raw OXTS (RTK GPS/IMU) of " + oxts.string() +
                                   " through calib_imu_to_velo.txt; world = the first frame's IMU";
  } else {
    source.notes.push_back(oxts.string() + " is absent: no reference trajectory");
  }
  return source;
}

}  // namespace colmap_lidar
