// `import_kitti`: a KITTI drive converted into our station dataset (docs/dataset_format.md), from
// either of KITTI's two layouts (colmap_ext/kitti_source.h reads them):
//   raw        DRIVE/image_0X/data/%010d.png, DRIVE/velodyne_points/data/%010d.bin, the day's
//              calib_cam_to_cam.txt and calib_velo_to_cam.txt; optional OXTS packets
//              (oxts/data/%010d.txt, with calib_imu_to_velo.txt) as the reference trajectory and
//              timestamps (image_0X/timestamps.txt, velodyne_points/timestamps_start/_end.txt)
//   odometry   SEQ/image_X/%06d.png, SEQ/velodyne/%06d.bin, SEQ/calib.txt (P0..P3, Tr),
//              SEQ/times.txt and, optionally, the benchmark's poses/NN.txt as the reference
// The left camera is PINHOLE from its rectified projection; ground_truth/cam_from_lidar.txt gets
// KITTI's reference extrinsic camX_from_velo, ground_truth/cam_from_world.txt the reference
// trajectory as camera poses when there is one (GPS/IMU: a reference, not perfect truth).
// Raw sweeps are marked for de-skewing (rig.json lidar.sweep); the odometry benchmark's scans are
// already motion-compensated and are marked as a moving platform only. rig.json gets a
// cam_from_lidar_guess only with `write_guess` (the reference perturbed, seeded).
#pragma once

#include "lidar/util/named_choice.h"

#include <cstdint>
#include <string>

namespace colmap_lidar {

enum class KittiFormat { kRaw, kOdometry };
inline constexpr NamedChoices<KittiFormat, 2> kKittiFormatNames = {
    {{"raw", KittiFormat::kRaw}, {"odometry", KittiFormat::kOdometry}}};

struct KittiImportOptions {
  KittiFormat format = KittiFormat::kRaw;
  std::string kitti_path;   // the raw drive folder (…_drive_NNNN_sync) or the odometry sequence
  std::string calib_path;   // raw: the day's folder with the calibration files
  std::string poses_path;   // odometry: the reference poses/NN.txt (optional)
  std::string output_path;  // the dataset to write
  // Frame indices first..last (last < 0: to the end), every step-th.
  int first = 0;
  int last = -1;
  int step = 1;
  // The left camera (0..2); camera + 1 is the right one when its images are there.
  int camera = 2;
  // false: a monocular dataset even if camera + 1 is there.
  bool use_right = true;
  bool write_guess = false;
  double guess_rotation_deg = 3.0;
  double guess_translation_m = 0.05;
  uint64_t seed = 0;
  bool overwrite = false;

  bool Check() const;
};

struct KittiImportSummary {
  int num_frames = 0;
  bool stereo = false;
  int width = 0, height = 0;
  bool reference_trajectory = false;
  bool frame_times = false;
  bool sweep_times = false;
};

// Writes OUTPUT.partial and renames it to OUTPUT when complete (nothing is left on failure). Throws
// std::runtime_error naming the file (and key or line): a missing calibration key (Tr, P_rect_0X), a
// frame without a cloud, a truncated .bin, an image of another size, a poses or times file with
// fewer lines than frames, a NaN in an OXTS packet, timestamps out of order, an existing output
// without `overwrite`.
KittiImportSummary ImportKitti(const KittiImportOptions& options);

}  // namespace colmap_lidar
