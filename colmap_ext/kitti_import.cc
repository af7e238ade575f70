#include "colmap_ext/kitti_import.h"

#include "colmap_ext/kitti_source.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/pose_perturbation.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/util/atomic_file.h"

#include <filesystem>
#include <iostream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

StationRig MakeRig(const KittiSource& source, const KittiImportOptions& options) {
  StationRig rig;
  rig.left = source.left.camera;
  rig.lidar_model = "HDL-64";
  rig.moving_platform = true;
  // Raw sweeps: one revolution per frame, from behind, counter-clockwise; de-skewed by the pipeline.
  if (!source.motion_compensated) rig.lidar_sweep = StationRig::LidarSweep();
  if (source.right) {
    rig.right = source.right->camera;
    rig.right_from_left = KittiRightFromLeft(source.left, *source.right);
  }
  if (options.write_guess) {
    rig.cam_from_lidar_guess = PerturbPose(source.left.cam_from_velo,
                                           options.guess_rotation_deg,
                                           options.guess_translation_m,
                                           options.seed);
  }
  return rig;
}

void CheckImageSize(const std::string& path, const colmap::Camera& camera) {
  const auto [width, height] = KittiImageSize(path);
  if (width != static_cast<int>(camera.width) || height != static_cast<int>(camera.height)) {
    throw std::runtime_error(path + ": the image is " + std::to_string(width) + "x" +
                             std::to_string(height) + " but the calibration says " +
                             std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
}

// Images and clouds, checked and copied frame by frame.
void CopyFrames(const KittiSource& source, const StationRig& rig, const fs::path& partial) {
  fs::create_directories(partial / "images" / "left");
  fs::create_directories(partial / "lidar");
  if (rig.IsStereo()) fs::create_directories(partial / "images" / "right");
  for (size_t k = 0; k < source.frames.size(); ++k) {
    const std::string& frame = source.frames[k];
    CheckImageSize(source.left_images[k], rig.left);
    CheckKittiCloud(source.clouds[k], frame);
    fs::copy_file(source.left_images[k], partial / "images" / "left" / (frame + ".png"));
    fs::copy_file(source.clouds[k], partial / "lidar" / (frame + ".bin"));
    if (rig.IsStereo()) {
      CheckImageSize(source.right_images[k], *rig.right);
      fs::copy_file(source.right_images[k], partial / "images" / "right" / (frame + ".png"));
    }
    if ((k + 1) % 20 == 0 || k + 1 == source.frames.size()) {
      std::cout << "import_kitti: " << k + 1 << "/" << source.frames.size() << " frames"
                << std::endl;
    }
  }
}

void WriteReferences(const KittiSource& source, int camera, const fs::path& partial) {
  fs::create_directories(partial / "ground_truth");
  WritePoseFile((partial / "ground_truth" / "cam_from_lidar.txt").string(),
                "KITTI's reference extrinsic of rectified camera " + std::to_string(camera) +
                    " from the Velodyne: [I | K^-1 P[:,3]] times the rectified camera 0 from the "
                    "Velodyne; cam_from_lidar (x_cam = R x_lidar + t)",
                source.left.cam_from_velo);
  if (!source.reference_cam_from_world.empty()) {
    std::map<std::string, colmap::Rigid3d> poses;
    for (size_t k = 0; k < source.frames.size(); ++k) {
      poses[source.frames[k]] = source.reference_cam_from_world[k];
    }
    WriteNamedPoses((partial / "ground_truth" / "cam_from_world.txt").string(),
                    "reference trajectory, not perfect truth: " + source.reference_description +
                        "; cam_from_world of rectified camera " + std::to_string(camera),
                    poses);
  }
  if (!source.frame_times.empty()) {
    WriteStationTimes((partial / "timestamps.txt").string(), source.frames, source.frame_times);
  }
  if (!source.sweep_times.empty()) {
    WriteSweepTimes((partial / "sweep_times.txt").string(), source.frames, source.sweep_times);
  }
}

}  // namespace

bool KittiImportOptions::Check() const {
  CHECK_OPTION(!kitti_path.empty());
  CHECK_OPTION(format == KittiFormat::kOdometry || !calib_path.empty());
  CHECK_OPTION(format == KittiFormat::kOdometry || poses_path.empty());
  CHECK_OPTION(!output_path.empty());
  CHECK_OPTION_GE(first, 0);
  CHECK_OPTION_GE(step, 1);
  CHECK_OPTION_GE(camera, 0);
  CHECK_OPTION_LE(camera, 3);
  CHECK_OPTION_GE(guess_rotation_deg, 0);
  CHECK_OPTION_GE(guess_translation_m, 0);
  return true;
}

KittiImportSummary ImportKitti(const KittiImportOptions& options) {
  THROW_CHECK(options.Check());
  const fs::path output(options.output_path);
  if (fs::exists(output) && !options.overwrite) {
    throw std::runtime_error(output.string() + " exists; pass --overwrite 1 to replace it");
  }
  const KittiSource source = options.format == KittiFormat::kRaw
                                 ? ReadKittiRawDrive(options)
                                 : ReadKittiOdometrySequence(options);
  for (const std::string& note : source.notes) std::cout << "import_kitti: " << note << std::endl;
  const StationRig rig = MakeRig(source, options);
  PartialOutputFolder partial_folder(options.output_path);
  const fs::path partial = partial_folder.Path();
  CopyFrames(source, rig, partial);
  WriteRigJson((partial / "rig.json").string(), rig);
  WriteReferences(source, options.camera, partial);
  partial_folder.Commit();
  KittiImportSummary summary;
  summary.num_frames = static_cast<int>(source.frames.size());
  summary.stereo = rig.IsStereo();
  summary.width = static_cast<int>(rig.left.width);
  summary.height = static_cast<int>(rig.left.height);
  summary.reference_trajectory = !source.reference_cam_from_world.empty();
  summary.frame_times = !source.frame_times.empty();
  summary.sweep_times = !source.sweep_times.empty();
  return summary;
}

}  // namespace colmap_lidar
