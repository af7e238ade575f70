// import_kitti: a KITTI raw drive into our station dataset (colmap_ext/kitti_import.h).
#include "bridge/exe/commands.h"
#include "colmap_ext/kitti_import.h"
#include "colmap_ext/logging.h"

#include "colmap/controllers/option_manager.h"

#include <iostream>

namespace colmap_lidar {

int RunImportKitti(int argc, char** argv) {
  KittiImportOptions import;
  int seed = 0;
  colmap::OptionManager options;
  options.AddRequiredOption("kitti_path", &import.kitti_path, "the drive folder (..._sync)");
  options.AddRequiredOption(
      "calib_path", &import.calib_path, "folder with calib_cam_to_cam.txt, calib_velo_to_cam.txt");
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
  import.seed = static_cast<uint64_t>(seed);
  THROW_CHECK(import.Check());
  const KittiImportSummary summary = ImportKittiDrive(import);
  std::cout << "import_kitti: wrote " << summary.num_frames << " frames ("
            << (summary.stereo ? "stereo" : "monocular") << ", " << summary.width << "x"
            << summary.height << ") to " << import.output_path
            << "; ground_truth/cam_from_lidar.txt holds KITTI's reference extrinsic" << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
