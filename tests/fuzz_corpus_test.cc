// Replays the fuzzers' corpus (tests/fuzz/corpus/<target>/, seeds and every input a fuzzer or a user
// once crashed us with) through the same readers as the fuzz targets, in the normal build: each file
// is read or refused with an exception naming the file; regression_* files must be refused.
#include "bridge/initialization/lidar_registration_files.h"
#include "colmap_ext/dense_workspace.h"
#include "colmap_ext/kitti_oxts.h"
#include "colmap_ext/station_dataset.h"
#include "colmap_ext/trajectory_files.h"
#include "lidar/cloud_io.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <map>
#include <string>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// The reader of each fuzz target, on a copy of the input named as the target expects.
const std::map<std::string, std::pair<std::string, std::function<void(const std::string&)>>>&
Readers() {
  static const std::map<std::string,
                        std::pair<std::string, std::function<void(const std::string&)>>>
      kReaders = {
          {"fuzz_cloud_pcd", {"in.pcd", [](const std::string& p) { ReadStationCloud(p); }}},
          {"fuzz_cloud_ply", {"in.ply", [](const std::string& p) { ReadStationCloud(p); }}},
          {"fuzz_cloud_bin", {"in.bin", [](const std::string& p) { ReadStationCloud(p); }}},
          {"fuzz_cloud_xyz", {"in.xyz", [](const std::string& p) { ReadStationCloud(p); }}},
          {"fuzz_rig_json", {"rig.json", [](const std::string& p) { ReadRigJson(p); }}},
          {"fuzz_cam_from_world_txt",
           {"poses.txt", [](const std::string& p) { ReadNamedPoses(p); }}},
          {"fuzz_cam_from_lidar_txt",
           {"cam_from_lidar.txt", [](const std::string& p) { ReadPoseFile(p); }}},
          {"fuzz_pairs_txt", {"pairs.txt", [](const std::string& p) { ReadLidarPairs(p); }}},
          {"fuzz_trajectory_txt",
           {"trajectory.txt",
            [](const std::string& p) { ReadTrajectoryFile(p, DetectTrajectoryFileFormat(p)); }}},
          {"fuzz_oxts_txt", {"oxts.txt", [](const std::string& p) { ReadOxtsPacket(p); }}},
          {"fuzz_timestamps_txt",
           {"timestamps.txt", [](const std::string& p) { ReadKittiTimestamps(p); }}},
          {"fuzz_depth_map",
           {"d.geometric.bin", [](const std::string& p) { ReadColmapDepthMap(p); }}},
      };
  return kReaders;
}

TEST(FuzzCorpus, EveryInputIsReadOrRefusedWithTheFileNamed) {
  const fs::path corpus = fs::path(COLMAP_LIDAR_SOURCE_DIR) / "tests" / "fuzz" / "corpus";
  testing::ScopedTempDir dir;
  size_t num_inputs = 0, num_regressions = 0;
  for (const auto& [target, reader] : Readers()) {
    ASSERT_TRUE(fs::is_directory(corpus / target)) << corpus / target;
    for (const auto& entry : fs::directory_iterator(corpus / target)) {
      const std::string copy = dir.File(reader.first);
      fs::copy_file(entry.path(), copy, fs::copy_options::overwrite_existing);
      const bool regression = entry.path().filename().string().rfind("regression_", 0) == 0;
      ++num_inputs;
      num_regressions += regression;
      try {
        reader.second(copy);
        EXPECT_FALSE(regression) << entry.path() << " was read, but it is a refused input";
      } catch (const std::exception& error) {
        EXPECT_TRUE(regression) << entry.path() << ": " << error.what();
        EXPECT_NE(std::string(error.what()).find(copy), std::string::npos)
            << entry.path() << ": the error does not name the file: " << error.what();
      }
    }
  }
  EXPECT_GE(num_inputs, 15u);
  EXPECT_GE(num_regressions, 5u);
}

}  // namespace
}  // namespace colmap_lidar
