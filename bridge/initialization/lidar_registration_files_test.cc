#include "bridge/initialization/lidar_registration_files.h"

#include "tests/testing/generic_poses.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>

#include <fstream>

namespace colmap_lidar {
namespace {

LidarPairRecord Record(const std::string& target, const std::string& source, double angle) {
  LidarPairRecord pair;
  pair.target = target;
  pair.source = source;
  pair.target_from_source = testing::Pose(angle, {0.3, -0.8, 0.5}, {1.25, -0.5, 0.0625});
  pair.num_inliers = 1234;
  pair.overlap = 0.8125;
  pair.rmse_m = 0.0123;
  pair.noise_m = 0.0101;
  pair.constraint_ratio = 0.0042;
  pair.weakest_axis = "tx";
  pair.degenerate = true;
  pair.from_identity = true;
  return pair;
}

TEST(LidarPairsFile, WhatIsWrittenIsReadBackWithEveryColumn) {
  testing::ScopedTempDir dir;
  const std::vector<LidarPairRecord> written = {Record("000", "001", 0.4),
                                                Record("001", "002", -1)};
  WriteLidarPairs(dir.File("pairs.txt"), written, {{"000", "002", "overlap 0.05 < 0.3"}});
  const std::vector<LidarPairRecord> read = ReadLidarPairs(dir.File("pairs.txt"));
  ASSERT_EQ(read.size(), written.size());  // the refused pair is a comment
  for (size_t k = 0; k < read.size(); ++k) {
    EXPECT_EQ(read[k].target, written[k].target);
    EXPECT_EQ(read[k].source, written[k].source);
    EXPECT_LT(
        read[k].target_from_source.rotation.angularDistance(written[k].target_from_source.rotation),
        1e-10);
    EXPECT_LT(
        (read[k].target_from_source.translation - written[k].target_from_source.translation).norm(),
        1e-10);
    EXPECT_EQ(read[k].num_inliers, 1234);
    EXPECT_DOUBLE_EQ(read[k].overlap, 0.8125);
    EXPECT_NEAR(read[k].rmse_m, 0.0123, 1e-6);
    EXPECT_NEAR(read[k].noise_m, 0.0101, 1e-6);
    EXPECT_NEAR(read[k].constraint_ratio, 0.0042, 1e-6);
    EXPECT_EQ(read[k].weakest_axis, "tx");
    EXPECT_TRUE(read[k].degenerate);
    EXPECT_TRUE(read[k].from_identity);
  }
  std::ifstream file(dir.File("pairs.txt"));
  const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("# refused 000 002: overlap 0.05 < 0.3"), std::string::npos);
}

TEST(LidarPairsFile, OlderTenColumnFilesAreReadAndMalformedLinesNamed) {
  testing::ScopedTempDir dir;
  std::ofstream(dir.File("old.txt")) << "# old\n000 001 1 0 0 0 0.5 0 0 800\n";
  const std::vector<LidarPairRecord> old = ReadLidarPairs(dir.File("old.txt"));
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(old[0].num_inliers, 800);
  EXPECT_DOUBLE_EQ(old[0].target_from_source.translation.x(), 0.5);
  EXPECT_FALSE(old[0].degenerate);
  for (const std::string bad : {"000 001 1 0 0 0 0.5 0 0\n",            // no inliers
                                "000 001 2 0 0 0 0.5 0 0 800\n",        // not a unit quaternion
                                "000 001 1 0 0 0 nan 0 0 800\n",        // not finite
                                "000 001 1 0 0 0 0.5 0 0 800 0.9 x\n",  // broken quality columns
                                "000 001 1 0 0 0 0.5 0 0 800 0.9 0.01 0.01 0.5 tx maybe bsc\n"}) {
    std::ofstream(dir.File("bad.txt")) << "# header\n" << bad;
    try {
      ReadLidarPairs(dir.File("bad.txt"));
      ADD_FAILURE() << "accepted " << bad;
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find("bad.txt:2"), std::string::npos) << error.what();
    }
  }
  EXPECT_THROW(ReadLidarPairs(dir.File("missing.txt")), std::runtime_error);
}

TEST(LidarPairsFile, LargestComponentIsFoundAcrossEdgeOrder) {
  const std::vector<LidarPairRecord> pairs = {
      Record("b", "c", 0.1), Record("x", "y", 0.1), Record("d", "a", 0.1), Record("c", "d", 0.1)};
  EXPECT_EQ(LargestLidarComponent(pairs), (std::vector<std::string>{"a", "b", "c", "d"}));
  EXPECT_TRUE(LargestLidarComponent({}).empty());
}

}  // namespace
}  // namespace colmap_lidar
