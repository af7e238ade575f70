#include "colmap_ext/station_dataset.h"

#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json ValidRig() {
  return json::parse(R"({
    "left":  {"model": "PINHOLE", "width": 64, "height": 48, "params": [50, 50, 32, 24]},
    "right": {"model": "OPENCV", "width": 64, "height": 48,
              "params": [50, 50, 32, 24, 0.01, 0, 0, 0]},
    "right_from_left": {"rotation": [1, 0, 0, 0], "translation": [-0.38, 0, 0]},
    "cam_from_lidar_guess": {"rotation": [0.5, -0.5, 0.5, -0.5], "translation": [0.1, -0.2, 0]},
    "lidar": {"model": "VLP-16", "range_noise_m": 0.01}
  })");
}

class StationDatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const char* d : {"images/left", "images/right", "lidar"}) {
      fs::create_directories(dir_.Path() / d);
    }
    WriteRig(ValidRig());
    for (const char* s : {"000", "001"}) {
      std::ofstream(dir_.File("images/left/") + s + ".png") << "x";
      std::ofstream(dir_.File("images/right/") + s + ".png") << "x";
      std::ofstream(dir_.File("lidar/") + s + ".pcd") << "x";
    }
  }
  void WriteRig(const json& rig) { std::ofstream(dir_.File("rig.json")) << rig.dump(); }

  // Expects ReadStationDataset to fail with a message naming `file` and containing `problem`.
  void ExpectError(const std::string& file, const std::string& problem) {
    try {
      ReadStationDataset(dir_.Path().string());
      ADD_FAILURE() << "no error; expected one about " << problem;
    } catch (const std::runtime_error& error) {
      const std::string what = error.what();
      EXPECT_NE(what.find(file), std::string::npos) << what;
      EXPECT_NE(what.find(problem), std::string::npos) << what;
    }
  }

  testing::ScopedTempDir dir_;
};

TEST_F(StationDatasetTest, ReadsAValidDataset) {
  const StationDataset dataset = ReadStationDataset(dir_.Path().string());
  EXPECT_EQ(dataset.stations, (std::vector<std::string>{"000", "001"}));
  EXPECT_EQ(dataset.rig.left.ModelName(), "PINHOLE");
  EXPECT_EQ(dataset.rig.right->params.size(), 8u);
  EXPECT_DOUBLE_EQ(dataset.rig.BaselineMeters(), 0.38);
  ASSERT_TRUE(dataset.rig.cam_from_lidar_guess.has_value());
  // w first in the file: [0.5, -0.5, 0.5, -0.5] is w=0.5, x=-0.5, ...
  EXPECT_DOUBLE_EQ(dataset.rig.cam_from_lidar_guess->rotation.w(), 0.5);
  EXPECT_DOUBLE_EQ(dataset.rig.cam_from_lidar_guess->rotation.x(), -0.5);
  EXPECT_EQ(dataset.LeftImageName(1), "left/001.png");
  EXPECT_FALSE(dataset.HasGroundTruth());
}

TEST_F(StationDatasetTest, RigJsonRoundTrips) {
  const StationRig rig = ReadRigJson(dir_.File("rig.json"));
  WriteRigJson(dir_.File("copy.json"), rig);
  const StationRig copy = ReadRigJson(dir_.File("copy.json"));
  EXPECT_EQ(copy.right->params, rig.right->params);
  EXPECT_EQ(copy.lidar_model, "VLP-16");
  EXPECT_FALSE(copy.lidar_sweep);  // tripod stations: accumulated clouds, not sweeps
  EXPECT_NEAR(
      copy.cam_from_lidar_guess->rotation.angularDistance(rig.cam_from_lidar_guess->rotation),
      0,
      1e-12);
}

// Sweeps of a moving platform (lidar.sweep) round-trip with their timing.
TEST_F(StationDatasetTest, LidarSweepRoundTrips) {
  StationRig rig = ReadRigJson(dir_.File("rig.json"));
  rig.lidar_sweep = StationRig::LidarSweep{90.0, false};
  WriteRigJson(dir_.File("copy.json"), rig);
  const StationRig copy = ReadRigJson(dir_.File("copy.json"));
  ASSERT_TRUE(copy.lidar_sweep);
  EXPECT_EQ(copy.lidar_sweep->start_azimuth_deg, 90.0);
  EXPECT_FALSE(copy.lidar_sweep->counter_clockwise);
}

// A guess with its sigma (a prior for the joint adjuster) round-trips; a half-given or
// non-positive sigma is refused naming the key.
TEST_F(StationDatasetTest, GuessSigmaRoundTripsAndBadOnesAreRefused) {
  EXPECT_FALSE(ReadRigJson(dir_.File("rig.json")).cam_from_lidar_guess_sigma);
  json rig = ValidRig();
  rig["cam_from_lidar_guess"]["sigma_rotation_deg"] = 0.5;
  rig["cam_from_lidar_guess"]["sigma_translation_m"] = 0.02;
  WriteRig(rig);
  WriteRigJson(dir_.File("copy.json"), ReadRigJson(dir_.File("rig.json")));
  const StationRig copy = ReadRigJson(dir_.File("copy.json"));
  ASSERT_TRUE(copy.cam_from_lidar_guess_sigma);
  EXPECT_EQ(copy.cam_from_lidar_guess_sigma->rotation_deg, 0.5);
  EXPECT_EQ(copy.cam_from_lidar_guess_sigma->translation_m, 0.02);
  rig["cam_from_lidar_guess"]["sigma_translation_m"] = 0;
  WriteRig(rig);
  ExpectError("rig.json", "'cam_from_lidar_guess.sigma_translation_m' must be a positive number");
  rig["cam_from_lidar_guess"].erase("sigma_translation_m");
  WriteRig(rig);
  ExpectError("rig.json", "needs both 'sigma_rotation_deg' and 'sigma_translation_m'");
}

TEST_F(StationDatasetTest, BadRigJsonNamesTheFileAndTheKey) {
  json rig = ValidRig();
  rig.erase("right_from_left");
  WriteRig(rig);
  ExpectError("rig.json", "missing key 'right_from_left'");

  rig = ValidRig();
  rig["left"].erase("params");
  WriteRig(rig);
  ExpectError("rig.json", "missing key 'left.params'");

  rig = ValidRig();
  rig["left"]["model"] = "PINHOL";
  WriteRig(rig);
  ExpectError("rig.json", "not a COLMAP camera model");

  rig = ValidRig();
  rig["right"]["params"] = {50, 50, 32};
  WriteRig(rig);
  ExpectError("rig.json", "must hold 8 values for model OPENCV");

  rig = ValidRig();
  rig["right_from_left"]["rotation"] = {1, 2, 3, 4};
  WriteRig(rig);
  ExpectError("rig.json", "not a unit quaternion");

  rig = ValidRig();
  rig["right_from_left"]["translation"] = {0, 0, 0};
  WriteRig(rig);
  ExpectError("rig.json", "baseline");

  rig = ValidRig();
  rig["lidar"]["sweep"] = {{"start_azimuth_deg", "behind"}};
  WriteRig(rig);
  ExpectError("rig.json", "'lidar.sweep.start_azimuth_deg' must be a finite number");

  std::ofstream(dir_.File("rig.json")) << "{ \"left\": ";
  ExpectError("rig.json", "not valid JSON");
}

TEST_F(StationDatasetTest, MissingImageOrCloudNamesTheFile) {
  fs::remove(dir_.File("images/right/001.png"));
  ExpectError("images/right/001.png", "missing right image of station 001");
  std::ofstream(dir_.File("images/right/001.png")) << "x";
  fs::remove(dir_.File("lidar/000.pcd"));
  ExpectError("lidar/000.pcd", "missing LiDAR cloud of station 000");
  std::ofstream(dir_.File("lidar/000.bin")) << "x";  // any supported format will do
  EXPECT_EQ(ReadStationDataset(dir_.Path().string()).cloud_paths[0], dir_.File("lidar/000.bin"));
}

// A monocular rig: no "right" in rig.json, no images/right/. It round-trips as monocular; a leftover
// images/right/ folder or a right_from_left without a right camera is refused naming rig.json.
TEST_F(StationDatasetTest, MonocularRigHasNoRightCamera) {
  json mono = ValidRig();
  mono.erase("right");
  mono.erase("right_from_left");
  WriteRig(mono);
  ExpectError("rig.json", "images/right");
  fs::remove_all(dir_.Path() / "images/right");
  const StationDataset dataset = ReadStationDataset(dir_.Path().string());
  EXPECT_FALSE(dataset.rig.IsStereo());
  EXPECT_EQ(dataset.rig.BaselineMeters(), 0.0);
  EXPECT_EQ(dataset.stations.size(), 2u);
  WriteRigJson(dir_.File("copy.json"), dataset.rig);
  EXPECT_FALSE(ReadRigJson(dir_.File("copy.json")).IsStereo());
  std::ifstream copy(dir_.File("copy.json"));
  EXPECT_FALSE(json::parse(copy).contains("right_from_left"));

  mono["right_from_left"] = ValidRig()["right_from_left"];
  WriteRig(mono);
  ExpectError("rig.json", "'right_from_left' without a 'right' camera");
}

TEST_F(StationDatasetTest, PoseFilesRoundTripWithWFirst) {
  const colmap::Rigid3d pose(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized())),
      Eigen::Vector3d(1.5, -0.25, 3));
  WritePoseFile(dir_.File("p.txt"), "test", pose);
  const colmap::Rigid3d read = ReadPoseFile(dir_.File("p.txt"));
  EXPECT_NEAR(read.rotation.angularDistance(pose.rotation), 0, 1e-15);
  EXPECT_NEAR((read.translation - pose.translation).norm(), 0, 1e-15);
  std::ifstream file(dir_.File("p.txt"));
  std::string line;
  while (std::getline(file, line) && line[0] == '#') {
  }
  EXPECT_DOUBLE_EQ(std::stod(line), pose.rotation.w());

  WriteNamedPoses(dir_.File("n.txt"), "test", {{"000", pose}, {"001", colmap::Rigid3d()}});
  const auto poses = ReadNamedPoses(dir_.File("n.txt"));
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_NEAR((poses.at("000").translation - pose.translation).norm(), 0, 1e-15);

  std::ofstream(dir_.File("bad.txt")) << "000 1 0 0\n";
  EXPECT_THROW(ReadNamedPoses(dir_.File("bad.txt")), std::runtime_error);
  std::ofstream(dir_.File("twice.txt")) << "000 1 0 0 0 0 0 0\n000 1 0 0 0 1 1 1\n";
  EXPECT_THROW(ReadNamedPoses(dir_.File("twice.txt")), std::runtime_error);
}

TEST(RestrictToStationsTest, KeepsTheNamedStationsWithTheirListsAndNamesAnUnknownOne) {
  StationDataset dataset;
  dataset.root = "/data";
  dataset.stations = {"000", "001", "002", "003"};
  dataset.cloud_paths = {"a", "b", "c", "d"};
  dataset.frame_times = {0.0, 0.1, 0.2, 0.3};
  const StationDataset restricted = RestrictToStations(dataset, {"003", "001"});
  EXPECT_EQ(restricted.stations, (std::vector<std::string>{"001", "003"}));
  EXPECT_EQ(restricted.cloud_paths, (std::vector<std::string>{"b", "d"}));
  EXPECT_EQ(restricted.frame_times, (std::vector<double>{0.1, 0.3}));
  EXPECT_TRUE(restricted.sweep_times.empty());
  try {
    RestrictToStations(dataset, {"001", "007"});
    FAIL() << "an unknown station was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("no station 007"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace colmap_lidar
