// `import_kitti`: a KITTI raw drive converted into our station dataset (docs/dataset_format.md):
//   DRIVE/image_0X/data/%010d.png          rectified images of camera X (2 by default; 0 for the grey
//                                          pair); camera X+1 when present makes a stereo rig
//   DRIVE/velodyne_points/data/%010d.bin   float32 x y z reflectance per point (copied as lidar/*.bin)
//   CALIB/calib_cam_to_cam.txt, calib_velo_to_cam.txt   (colmap_ext/kitti_calibration.h)
// Frames are matched by index (timestamps.txt and OXTS are optional and not read). The left camera is
// PINHOLE from P_rect_0X; ground_truth/cam_from_lidar.txt gets KITTI's reference extrinsic
// camX_from_velo = [I | K^-1 P_rect_0X[:,3]] R_rect_00 [R|T]; a drive has no ground-truth poses or
// surface. rig.json gets a cam_from_lidar_guess only with `write_guess` (the reference perturbed, seeded,
// as the simulator does). Quaternions are written w first.
#pragma once

#include <cstdint>
#include <string>

namespace colmap_lidar {

struct KittiImportOptions {
  std::string kitti_path;   // the drive folder (…_drive_NNNN_sync)
  std::string calib_path;   // the day's folder with the two calibration files
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
};

// Writes OUTPUT.partial and renames it to OUTPUT when complete (nothing is left on failure). Throws std::runtime_error naming the
// file (and key or line): a missing P_rect_0X, a frame without a cloud, a truncated .bin, an image of
// another size than S_rect_0X, an existing output without `overwrite`.
KittiImportSummary ImportKittiDrive(const KittiImportOptions& options);

}  // namespace colmap_lidar
