// calibrate_edges (Levinson & Thrun's baseline) through the CLI: what it writes, and what it refuses.
// Its accuracy is checked on real data (tests/kitti_sample_test.cc): on the simulator's textured
// surfaces the edge objective is flat (docs/edge_calibration.md).
#include "bridge/simulation/simulate_dataset.h"
#include "colmap_ext/station_dataset.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;
const std::string kCli = COLMAP_LIDAR_CLI_EXE;

class EdgeCalibrationTest : public ::testing::Test {
 protected:
  void SetUp() override { sim::SimulateSmallDataset(dir_.File("dataset"), 3, 0.25, 20000); }
  testing::ScopedTempDir dir_;
};

TEST_F(EdgeCalibrationTest, WritesTheExtrinsicAReportAndAPlot) {
  const auto result = RunCommand(kCli + " calibrate_edges --dataset_path " + dir_.File("dataset") +
                                 " --output_path " + dir_.File("edges") +
                                 " --rotation_steps_deg 0.5,0.1 --translation_steps_m 0.02,0.01");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NO_THROW(ReadPoseFile(dir_.File("edges/cam_from_lidar.txt")));
  std::ifstream file(dir_.File("edges/report.json"));
  const nlohmann::json report = nlohmann::json::parse(file);
  EXPECT_EQ(report["num_stations"].get<int>(), 3);
  EXPECT_EQ(report["moves_per_level"].size(), 2u);
  EXPECT_GT(report["num_discontinuity_points"].get<int>(), 0);
  // J at the start and after each move.
  EXPECT_EQ(
      report["objective_history"].size(),
      1 + report["moves_per_level"][0].get<size_t>() + report["moves_per_level"][1].get<size_t>());
  EXPECT_TRUE(report.contains("fraction_lower_F_c"));
  EXPECT_TRUE(fs::exists(dir_.File("edges/edges_001.png")));
}

// --profile_axis: J along one camera axis instead of the grid, with its plot; a bad axis is refused.
TEST_F(EdgeCalibrationTest, ProfilesOneAxisAndRefusesABadOne) {
  const auto result = RunCommand(kCli + " calibrate_edges --dataset_path " + dir_.File("dataset") +
                                 " --output_path " + dir_.File("profile") +
                                 " --profile_axis 0,0,1 --profile_half_range_deg 0.3");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::ifstream file(dir_.File("profile/report.json"));
  const nlohmann::json report = nlohmann::json::parse(file);
  EXPECT_EQ(report["angles_deg"].size(), 61u);
  EXPECT_EQ(report["objective"].size(), 61u);
  EXPECT_LE(std::abs(report["peak_deg"].get<double>()), 0.3);
  EXPECT_GE(report["sigma_deg"].get<double>(), 0);
  EXPECT_TRUE(fs::exists(dir_.File("profile/profile.png")));
  EXPECT_NO_THROW(ReadPoseFile(dir_.File("profile/cam_from_lidar.txt")));
  const auto bad = RunCommand(kCli + " calibrate_edges --dataset_path " + dir_.File("dataset") +
                              " --output_path " + dir_.File("none") + " --profile_axis 0,0");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("--profile_axis needs x,y,z"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir_.File("none")));
}

TEST_F(EdgeCalibrationTest, BadInputIsOneErrorNamingItAndNoOutput) {
  const auto missing = RunCommand(kCli + " calibrate_edges --dataset_path " + dir_.File("dataset") +
                                  " --cam_from_lidar " + dir_.File("missing.txt") +
                                  " --output_path " + dir_.File("none"));
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("missing.txt"), std::string::npos) << missing.output;
  const auto steps = RunCommand(kCli + " calibrate_edges --dataset_path " + dir_.File("dataset") +
                                " --output_path " + dir_.File("none") +
                                " --rotation_steps_deg 1,0.1" + " --translation_steps_m 0.05");
  EXPECT_NE(steps.exit_code, 0);
  EXPECT_FALSE(fs::exists(dir_.File("none")));
  EXPECT_FALSE(fs::exists(dir_.File("none.partial")));
}

}  // namespace
}  // namespace colmap_lidar
