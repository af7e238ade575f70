// import_kitti: a KITTI raw drive or odometry sequence into our station dataset
// (colmap_ext/kitti_import.h).
#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "colmap_ext/kitti_import.h"
#include "colmap_ext/logging.h"

#include <iostream>

namespace colmap_lidar {

int RunImportKitti(int argc, char** argv) {
  KittiImportOptions import;
  int seed = 0;
  std::string sequence_path;
  CommandOptions options;
  options.AddChoiceOption(
      "format", &import.format, kKittiFormatNames, "a raw drive or an odometry benchmark sequence");
  options.AddDefaultOption("kitti_path", &import.kitti_path, "raw: the drive folder (..._sync)");
  options.AddDefaultOption(
      "sequence_path", &sequence_path, "odometry: the sequence folder (calib.txt, image_2, ...)");
  options.AddDefaultOption("calib_path",
                           &import.calib_path,
                           "raw: folder with calib_cam_to_cam.txt, calib_velo_to_cam.txt "
                           "(and calib_imu_to_velo.txt for OXTS)");
  options.AddDefaultOption(
      "poses_path", &import.poses_path, "odometry: the reference poses/NN.txt (optional)");
  options.AddRequiredOption("output_path", &import.output_path);
  options.AddDefaultOption("first", &import.first, "first frame index");
  options.AddDefaultOption("last", &import.last, "last frame index; -1: to the end");
  options.AddDefaultOption("step", &import.step, "every step-th frame");
  options.AddDefaultOption(
      "camera", &import.camera, "left camera 0..3 (2: colour; camera + 1 is the right one)");
  options.AddDefaultOption("use_right", &import.use_right, "0: monocular even with camera + 1");
  options.AddDefaultOption("write_guess",
                           &import.write_guess,
                           "write cam_from_lidar_guess (the reference, perturbed) into rig.json");
  options.AddDefaultOption("guess_rotation_deg", &import.guess_rotation_deg);
  options.AddDefaultOption("guess_translation_m", &import.guess_translation_m);
  options.AddDefaultOption("seed", &seed);
  options.AddDefaultOption("overwrite", &import.overwrite);
  options.Parse(argc, argv);
  if (import.format == KittiFormat::kOdometry) {
    THROW_CHECK(import.kitti_path.empty() || sequence_path.empty())
        << "give the sequence as --sequence_path only";
    if (!sequence_path.empty()) import.kitti_path = sequence_path;
  } else {
    THROW_CHECK(sequence_path.empty()) << "--sequence_path is for --format odometry";
  }
  THROW_CHECK(!import.kitti_path.empty())
      << (import.format == KittiFormat::kRaw ? "--kitti_path" : "--sequence_path")
      << " is required";
  THROW_CHECK(import.format == KittiFormat::kOdometry || !import.calib_path.empty())
      << "--calib_path is required for a raw drive";
  import.seed = static_cast<uint64_t>(seed);
  THROW_CHECK(import.Check());
  const KittiImportSummary summary = ImportKitti(import);
  std::cout << "import_kitti: wrote " << summary.num_frames << " frames ("
            << (summary.stereo ? "stereo" : "monocular") << ", " << summary.width << "x"
            << summary.height << ") to " << import.output_path
            << "; ground_truth/cam_from_lidar.txt holds KITTI's reference extrinsic"
            << (summary.reference_trajectory ? ", ground_truth/cam_from_world.txt the reference "
                                               "trajectory"
                                             : "")
            << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
