#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "colmap_ext/extension_database.h"
#include "colmap_ext/logging.h"

#include "colmap/scene/database.h"

#include <filesystem>
#include <iostream>

namespace colmap_lidar {

int RunDatabaseCreator(int argc, char** argv) {
  CommandOptions options;
  options.AddDatabaseOptions();
  options.Parse(argc, argv);
  {
    colmap::Database database(*options.database_path);  // creates COLMAP's tables if absent
  }
  ExtensionDatabase extension(*options.database_path);
  std::cout << "Database " << *options.database_path
            << " has COLMAP's and colmap-lidar's tables (depth_priors, "
               "lidar_frames, rig)"
            << std::endl;
  return EXIT_SUCCESS;
}

int RunDatabaseInfo(int argc, char** argv) {
  CommandOptions options;
  options.AddDatabaseOptions();
  options.Parse(argc, argv);
  const std::string& path = *options.database_path;
  THROW_CHECK(std::filesystem::is_regular_file(path)) << "Database file does not exist: " << path;
  // Our read-only connection first: it rejects a non-COLMAP file without creating anything.
  const ExtensionDatabase extension(path, ExtensionDatabase::Mode::kReadOnly);
  const colmap::Database database(path);
  std::cout << "images:        " << database.NumImages() << "\n"
            << "cameras:       " << database.NumCameras() << "\n"
            << "keypoints:     " << database.NumKeypoints() << "\n"
            << "verified pairs: " << database.NumVerifiedImagePairs() << "\n"
            << "depth priors:  " << extension.NumDepthPriors() << "\n"
            << "lidar frames:  " << extension.ReadLidarFrames().size() << "\n";
  const std::optional<StereoRig> rig = extension.ReadRig();
  if (rig) {
    std::cout << "rig:           baseline " << rig->BaselineMeters() << " m, right camera "
              << rig->right_camera.ModelName() << " " << rig->right_camera.width << "x"
              << rig->right_camera.height << "\n";
  } else {
    std::cout << "rig:           none\n";
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
