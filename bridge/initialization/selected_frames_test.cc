#include "bridge/initialization/selected_frames.h"

#include "bridge/initialization/lidar_registration_files.h"
#include "colmap_ext/station_dataset.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace colmap_lidar {
namespace {

// Twelve frames along x, 1 m apart, standing still at frames 4-8 (frame 3's place), a slight turn
// per frame; consecutive edges with quality numbers that say which frame they belong to, except
// between 10 and 11 (two components).
void WriteDrive(const testing::ScopedTempDir& dir) {
  std::filesystem::create_directories(dir.File("lidar"));
  std::map<std::string, colmap::Rigid3d> poses;
  std::vector<LidarPairRecord> pairs;
  double x = 0;
  for (int i = 0; i < 12; ++i) {
    if (i > 0 && (i <= 3 || i >= 9)) x += 1;
    const std::string name = "0" + std::string(i < 10 ? "0" : "") + std::to_string(i);
    poses[name] =
        colmap::Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.001 * i, Eigen::Vector3d::UnitZ())),
                        Eigen::Vector3d(x, 0.01 * i, 0));
    if (i == 0 || i == 11) continue;
    LidarPairRecord pair;
    pair.target = std::prev(poses.end(), 2)->first;
    pair.source = name;
    pair.target_from_source = colmap::Inverse(std::prev(poses.end(), 2)->second) * poses[name];
    pair.num_inliers = 1000 + i;
    pair.overlap = 0.9 - 0.01 * i;
    pair.rmse_m = 0.01 * i;
    pair.noise_m = 0.001 * i;
    pair.constraint_ratio = 0.5 - 0.01 * i;
    pair.weakest_axis = "t" + std::to_string(i);
    pairs.push_back(pair);
  }
  WriteNamedPoses(dir.File("lidar/lidar_poses.txt"), "test", poses);
  WriteLidarPairs(dir.File("lidar/pairs.txt"), pairs, {});
}

TEST(SelectedFramesTest, AStandstillIsLeftOutAndItsFramesBridgedByTheTrajectory) {
  testing::ScopedTempDir dir;
  WriteDrive(dir);
  const SelectedFramesSummary summary =
      WriteSelectedFrames(dir.File("lidar"), dir.File("selected"), FrameSelectionOptions());
  EXPECT_EQ(summary.num_frames, 12u);
  EXPECT_EQ(summary.num_kept, 7u);  // 0-3, 9, 10, 11
  EXPECT_EQ(summary.num_composed_edges, 1u);
  EXPECT_FALSE(std::filesystem::exists(dir.File("selected.partial")));
  const std::vector<std::string> kept = ReadSelectedFrames(dir.File("selected"));
  EXPECT_EQ(kept, (std::vector<std::string>{"000", "001", "002", "003", "009", "010", "011"}));
  EXPECT_EQ(ReadNamedPoses(dir.File("selected/lidar_poses.txt")).size(), 7u);

  const std::vector<LidarPairRecord> pairs = ReadLidarPairs(dir.File("selected/pairs.txt"));
  // 0-1, 1-2, 2-3, 9-10 kept as they are; 3-9 composed; 10-11 had no edge and gets none.
  ASSERT_EQ(pairs.size(), 5u);
  const LidarPairRecord& composed = pairs.back();
  EXPECT_EQ(composed.target, "003");
  EXPECT_EQ(composed.source, "009");
  const auto poses = ReadNamedPoses(dir.File("lidar/lidar_poses.txt"));
  const colmap::Rigid3d truth = colmap::Inverse(poses.at("003")) * poses.at("009");
  EXPECT_LT((composed.target_from_source.translation - truth.translation).norm(), 1e-9);
  EXPECT_LT(composed.target_from_source.rotation.angularDistance(truth.rotation), 1e-9);
  // The weakest of the edges 3-4 ... 8-9.
  EXPECT_EQ(composed.num_inliers, 1004);
  EXPECT_NEAR(composed.overlap, 0.81, 1e-9);
  EXPECT_NEAR(composed.rmse_m, 0.09, 1e-6);
  EXPECT_NEAR(composed.constraint_ratio, 0.41, 1e-6);
  EXPECT_EQ(composed.weakest_axis, "t9");
}

TEST(SelectedFramesTest, MissingAndMalformedFilesAreNamed) {
  testing::ScopedTempDir dir;
  EXPECT_THROW(WriteSelectedFrames(dir.File("none"), dir.File("selected"), {}), std::runtime_error);
  EXPECT_FALSE(std::filesystem::exists(dir.File("selected")));
  std::filesystem::create_directories(dir.File("bad"));
  std::ofstream(dir.File("bad/selected_frames.txt")) << "000 first\n001 sideways\n";
  try {
    ReadSelectedFrames(dir.File("bad"));
    FAIL() << "a bad reason was read";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("selected_frames.txt:2"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace colmap_lidar
