// The KITTI odometry benchmark's layout (Geiger, Lenz, Urtasun, "Are we ready for Autonomous
// Driving?", CVPR 2012): SEQ/image_X/%06d.png, SEQ/velodyne/%06d.bin, SEQ/calib.txt, SEQ/times.txt,
// and poses/NN.txt (world_from_cam0 of the rectified camera 0 per frame; world = frame 0).
#include "colmap_ext/kitti_source.h"
#include "colmap_ext/trajectory_files.h"

#include <algorithm>
#include <filesystem>

namespace colmap_lidar {

namespace fs = std::filesystem;

namespace {

// cam_from_world of the left camera from the benchmark's world_from_cam0:
// camX_from_world = [I | K^-1 P_X[:,3]] cam0_from_world.
std::vector<colmap::Rigid3d> ReferenceCamFromWorld(const std::string& poses_path,
                                                   const KittiCamera& left,
                                                   const std::vector<int>& indices) {
  const int last = *std::max_element(indices.begin(), indices.end());
  const std::vector<colmap::Rigid3d> world_from_cam0 =
      ReadKittiPoses(poses_path, static_cast<size_t>(last) + 1);
  const colmap::Rigid3d cam_from_cam0(Eigen::Quaterniond::Identity(), left.projection_offset);
  std::vector<colmap::Rigid3d> cam_from_world;
  for (const int index : indices) {
    cam_from_world.push_back(cam_from_cam0 * colmap::Inverse(world_from_cam0[index]));
  }
  return cam_from_world;
}

}  // namespace

KittiSource ReadKittiOdometrySequence(const KittiImportOptions& options) {
  const fs::path sequence(options.kitti_path);
  const auto image_folder = [&](int camera) {
    return (sequence / ("image_" + std::to_string(camera))).string();
  };
  const auto selected = SelectKittiFrames(image_folder(options.camera), options);
  KittiSource source;
  std::vector<int> indices;
  for (const auto& [frame, index] : selected) {
    source.frames.push_back(frame);
    indices.push_back(index);
    source.left_images.push_back(
        (fs::path(image_folder(options.camera)) / (frame + ".png")).string());
    source.clouds.push_back((sequence / "velodyne" / (frame + ".bin")).string());
  }
  const auto [width, height] = KittiImageSize(source.left_images.front());
  const std::string calib = (sequence / "calib.txt").string();
  source.left = ReadKittiOdometryCamera(calib, options.camera, width, height);
  source.right_images = KittiRightImages(image_folder(options.camera + 1), source.frames, options);
  if (!source.right_images.empty()) {
    source.right = ReadKittiOdometryCamera(calib, options.camera + 1, width, height);
  }
  source.motion_compensated = true;
  const int last = *std::max_element(indices.begin(), indices.end());
  const fs::path times = sequence / "times.txt";
  if (fs::is_regular_file(times)) {
    const std::vector<double> all = ReadKittiTimes(times.string(), static_cast<size_t>(last) + 1);
    for (const int index : indices) source.frame_times.push_back(all[index]);
  } else {
    source.notes.push_back(times.string() + " is absent: no frame times");
  }
  if (options.poses_path.empty()) {
    source.notes.push_back("no --poses_path: no reference trajectory");
  } else {
    source.reference_cam_from_world =
        ReferenceCamFromWorld(options.poses_path, source.left, indices);
    source.reference_description =
        "KITTI odometry reference poses (RTK GPS/IMU) of " + options.poses_path;
  }
  return source;
}

}  // namespace colmap_lidar
