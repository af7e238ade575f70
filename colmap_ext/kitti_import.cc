#include "colmap_ext/kitti_import.h"

#include "colmap_ext/atomic_file.h"
#include "colmap_ext/kitti_calibration.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/pose_perturbation.h"
#include "colmap_ext/station_dataset.h"

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <vector>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

fs::path ImageFolder(const KittiImportOptions& options, int camera) {
  return fs::path(options.kitti_path) / ("image_0" + std::to_string(camera)) / "data";
}

fs::path CloudPath(const KittiImportOptions& options, const std::string& frame) {
  return fs::path(options.kitti_path) / "velodyne_points" / "data" / (frame + ".bin");
}

// The frames of the left camera (file stems, sorted) within first..last, every step-th.
std::vector<std::string> SelectFrames(const KittiImportOptions& options) {
  const fs::path folder = ImageFolder(options, options.camera);
  if (!fs::is_directory(folder)) {
    throw std::runtime_error("no images of camera " + std::to_string(options.camera) + ": " +
                             folder.string() + " does not exist");
  }
  std::vector<std::string> all;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() == ".png") all.push_back(entry.path().stem().string());
  }
  std::sort(all.begin(), all.end());
  std::vector<std::string> frames;
  for (const std::string& frame : all) {
    int index = -1;
    try {
      index = std::stoi(frame);
    } catch (const std::exception&) {
      throw std::runtime_error(folder.string() + "/" + frame +
                               ".png: not a KITTI frame name (%010d.png)");
    }
    if (index < options.first || (options.last >= 0 && index > options.last) ||
        (index - options.first) % options.step != 0) {
      continue;
    }
    frames.push_back(frame);
  }
  if (frames.empty()) throw std::runtime_error("no frames selected in " + folder.string());
  return frames;
}

// A KITTI .bin holds float32 x y z reflectance: a whole, non-empty number of 16-byte points.
void CheckCloud(const fs::path& path, const std::string& frame) {
  if (!fs::is_regular_file(path)) {
    throw std::runtime_error(path.string() + ": frame " + frame + " has no Velodyne cloud");
  }
  const uintmax_t size = fs::file_size(path);
  if (size == 0 || size % 16 != 0) {
    throw std::runtime_error(path.string() + ": truncated KITTI cloud (" + std::to_string(size) +
                             " bytes, not a whole number of 16-byte points)");
  }
}

void CheckImageSize(const fs::path& path, const colmap::Camera& camera) {
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) throw std::runtime_error(path.string() + ": cannot read the image");
  if (image.cols != static_cast<int>(camera.width) ||
      image.rows != static_cast<int>(camera.height)) {
    throw std::runtime_error(path.string() + ": the image is " + std::to_string(image.cols) + "x" +
                             std::to_string(image.rows) + " but S_rect says " +
                             std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
}

// The right camera's images exist for every selected frame.
bool HasRightImages(const KittiImportOptions& options, const std::vector<std::string>& frames) {
  if (!options.use_right || options.camera == 3) return false;
  for (const std::string& frame : frames) {
    if (!fs::is_regular_file(ImageFolder(options, options.camera + 1) / (frame + ".png"))) {
      return false;
    }
  }
  return true;
}

}  // namespace

bool KittiImportOptions::Check() const {
  CHECK_OPTION(!kitti_path.empty());
  CHECK_OPTION(!calib_path.empty());
  CHECK_OPTION(!output_path.empty());
  CHECK_OPTION_GE(first, 0);
  CHECK_OPTION_GE(step, 1);
  CHECK_OPTION_GE(camera, 0);
  CHECK_OPTION_LE(camera, 3);
  CHECK_OPTION_GE(guess_rotation_deg, 0);
  CHECK_OPTION_GE(guess_translation_m, 0);
  return true;
}

KittiImportSummary ImportKittiDrive(const KittiImportOptions& options) {
  THROW_CHECK(options.Check());
  const fs::path output(options.output_path);
  if (fs::exists(output) && !options.overwrite) {
    throw std::runtime_error(output.string() + " exists; pass --overwrite 1 to replace it");
  }
  const KittiCamera left = ReadKittiCamera(options.calib_path, options.camera);
  const std::vector<std::string> frames = SelectFrames(options);
  const bool stereo = HasRightImages(options, frames);
  StationRig rig;
  rig.left = left.camera;
  rig.lidar_model = "HDL-64";
  rig.lidar_sweep = StationRig::LidarSweep();  // one revolution per frame, from behind, ccw
  if (stereo) {
    const KittiCamera right = ReadKittiCamera(options.calib_path, options.camera + 1);
    rig.right = right.camera;
    rig.right_from_left = KittiRightFromLeft(left, right);
  }
  if (options.write_guess) {
    rig.cam_from_lidar_guess = PerturbPose(
        left.cam_from_velo, options.guess_rotation_deg, options.guess_translation_m, options.seed);
  }

  PartialOutputFolder partial_folder(options.output_path);
  const fs::path partial = partial_folder.Path();
  fs::create_directories(partial / "images" / "left");
  fs::create_directories(partial / "lidar");
  fs::create_directories(partial / "ground_truth");
  if (stereo) fs::create_directories(partial / "images" / "right");
  for (size_t k = 0; k < frames.size(); ++k) {
    const std::string& frame = frames[k];
    const fs::path left_image = ImageFolder(options, options.camera) / (frame + ".png");
    CheckImageSize(left_image, rig.left);
    CheckCloud(CloudPath(options, frame), frame);
    fs::copy_file(left_image, partial / "images" / "left" / (frame + ".png"));
    fs::copy_file(CloudPath(options, frame), partial / "lidar" / (frame + ".bin"));
    if (stereo) {
      const fs::path right_image = ImageFolder(options, options.camera + 1) / (frame + ".png");
      CheckImageSize(right_image, *rig.right);
      fs::copy_file(right_image, partial / "images" / "right" / (frame + ".png"));
    }
    if ((k + 1) % 20 == 0 || k + 1 == frames.size()) {
      std::cout << "import_kitti: " << k + 1 << "/" << frames.size() << " frames" << std::endl;
    }
  }
  WriteRigJson((partial / "rig.json").string(), rig);
  WritePoseFile((partial / "ground_truth" / "cam_from_lidar.txt").string(),
                "KITTI's reference extrinsic of rectified camera " +
                    std::to_string(options.camera) +
                    " from the Velodyne: [I | K^-1 P_rect[:,3]] R_rect_00 [R|T]; "
                    "cam_from_lidar (x_cam = R x_lidar + t)",
                left.cam_from_velo);
  partial_folder.Commit();
  KittiImportSummary summary;
  summary.num_frames = static_cast<int>(frames.size());
  summary.stereo = stereo;
  summary.width = static_cast<int>(rig.left.width);
  summary.height = static_cast<int>(rig.left.height);
  return summary;
}

}  // namespace colmap_lidar
