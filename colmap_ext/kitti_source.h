// What import_kitti reads from a KITTI raw drive or odometry sequence before it writes our dataset:
// one reader per layout (kitti_raw_drive.cc, kitti_odometry_sequence.cc) fills a KittiSource.
#pragma once

#include "colmap_ext/kitti_calibration.h"
#include "colmap_ext/kitti_import.h"

#include "colmap/geometry/rigid3.h"

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace colmap_lidar {

struct KittiSource {
  std::vector<std::string> frames;                             // station names: the file stems
  std::vector<std::string> left_images, right_images, clouds;  // right_images empty: monocular
  KittiCamera left;
  std::optional<KittiCamera> right;
  // The reference trajectory as poses of the left camera (empty: none) and what it is.
  std::vector<colmap::Rigid3d> reference_cam_from_world;
  std::string reference_description;
  std::vector<double> frame_times;                     // [s] per frame (empty: none)
  std::vector<std::pair<double, double>> sweep_times;  // start, end [s] per frame (empty: none)
  // Scans already compensated for the platform's motion (the odometry benchmark's).
  bool motion_compensated = false;
  // What the reader could not find (printed once by the importer).
  std::vector<std::string> notes;
};

KittiSource ReadKittiRawDrive(const KittiImportOptions& options);
KittiSource ReadKittiOdometrySequence(const KittiImportOptions& options);

// Shared by both readers.
// The frames (file stems, sorted) of FOLDER/*.png within first..last, every step-th, with their
// numeric indices; throws naming the folder or a file that is not a frame name.
std::vector<std::pair<std::string, int>> SelectKittiFrames(const std::string& folder,
                                                           const KittiImportOptions& options);
// A KITTI .bin holds float32 x y z reflectance: a whole, non-empty number of 16-byte points.
void CheckKittiCloud(const std::string& path, const std::string& frame);
// The right camera's images for every frame in `right_folder` (and wanted): their paths, else none.
std::vector<std::string> KittiRightImages(const std::string& right_folder,
                                          const std::vector<std::string>& frames,
                                          const KittiImportOptions& options);
// The size of the first image; throws naming it when it cannot be read.
std::pair<int, int> KittiImageSize(const std::string& path);

}  // namespace colmap_lidar
