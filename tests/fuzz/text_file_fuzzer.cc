// libFuzzer target: our parsers of the text files a user writes or edits by hand (FUZZ_FILE): rig.json
// (colmap_ext ReadRigJson), cam_from_world.txt / lidar_poses.txt (ReadNamedPoses), cam_from_lidar.txt
// (ReadPoseFile), pairs.txt (bridge ReadLidarPairs), trajectory files in any format
// (ReadTrajectoryFile after DetectTrajectoryFileFormat), OXTS packets and KITTI timestamps. Errors are std::exception with the file named;
// anything else is a finding.
#include "bridge/initialization/lidar_registration_files.h"
#include "colmap_ext/kitti_oxts.h"
#include "colmap_ext/station_dataset.h"
#include "colmap_ext/trajectory_files.h"
#include "tests/fuzz/fuzz_input_file.h"

#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = colmap_lidar::WriteFuzzInput(data, size, std::string("_") + FUZZ_FILE);
  if (path.empty()) return 0;
  const std::string kind = FUZZ_FILE;
  try {
    if (kind == "rig.json") {
      colmap_lidar::ReadRigJson(path);
    } else if (kind == "cam_from_world.txt") {
      colmap_lidar::ReadNamedPoses(path);
    } else if (kind == "cam_from_lidar.txt") {
      colmap_lidar::ReadPoseFile(path);
    } else if (kind == "trajectory.txt") {
      colmap_lidar::ReadTrajectoryFile(path, colmap_lidar::DetectTrajectoryFileFormat(path));
    } else if (kind == "oxts.txt") {
      colmap_lidar::ReadOxtsPacket(path);
    } else if (kind == "timestamps.txt") {
      colmap_lidar::ReadKittiTimestamps(path);
    } else {
      colmap_lidar::ReadLidarPairs(path);
    }
  } catch (const std::exception&) {
  }
  std::remove(path.c_str());
  return 0;
}
