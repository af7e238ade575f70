// import_kitti on a drive the simulator writes in KITTI raw's exact layout (simulate_dataset --layout
// kitti: image_02/image_03/velodyne_points folders, calib_cam_to_cam.txt and calib_velo_to_cam.txt in the
// published format with a generic R_rect_00 and KITTI-like P_rect offsets): the import must give back
// the simulator's truth (extrinsic to 1e-9, intrinsics, baseline, frames), select frames, and refuse bad
// drives naming the file, leaving nothing behind. The real sample is in kitti_sample_test.cc.
#include "bridge/simulation/sensor_pod.h"
#include "bridge/simulation/simulate_dataset.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;

const std::string kCli = COLMAP_LIDAR_CLI_EXE;

class KittiImportTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::ScopedTempDir("colmap_lidar_kitti_import");
    sim::SimulationOptions options;
    options.scene = "street";
    options.motion = sim::Motion::kDrive;
    options.layout = sim::DatasetLayout::kKitti;
    options.output_path = dir_->File("kitti");
    options.num_stations = 5;
    options.image_scale = 0.5;
    options.lidar_points = 20000;
    sim::SimulateDataset(options);
  }
  static void TearDownTestSuite() { delete dir_; }

  static std::string Drive() { return dir_->File("kitti/drive"); }
  static std::string Calib() { return dir_->File("kitti/calibration"); }

  // import_kitti with `arguments` into a fresh folder; returns the output folder.
  static testing::CommandResult Import(const std::string& output,
                                       const std::string& arguments,
                                       const std::string& drive = Drive(),
                                       const std::string& calib = Calib()) {
    return RunCommand(kCli + " import_kitti --kitti_path " + drive + " --calib_path " + calib +
                      " --output_path " + output + " " + arguments);
  }

  static testing::ScopedTempDir* dir_;
};

testing::ScopedTempDir* KittiImportTest::dir_ = nullptr;

TEST_F(KittiImportTest, GivesBackTheSimulatorsTruth) {
  const std::string output = dir_->File("imported");
  const auto run = Import(output, "");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const StationDataset dataset = ReadStationDataset(output);
  EXPECT_EQ(dataset.stations,
            (std::vector<std::string>{
                "0000000000", "0000000001", "0000000002", "0000000003", "0000000004"}));
  ASSERT_TRUE(dataset.rig.IsStereo());
  EXPECT_FALSE(dataset.rig.cam_from_lidar_guess);
  // KITTI's HDL-64 sweeps, one revolution per frame from behind, counter-clockwise: the pipeline
  // de-skews them without being asked.
  ASSERT_TRUE(dataset.rig.lidar_sweep);
  EXPECT_EQ(dataset.rig.lidar_sweep->start_azimuth_deg, 180.0);
  EXPECT_TRUE(dataset.rig.lidar_sweep->counter_clockwise);
  const StationRig truth_rig = sim::MakeDriveRig(0.5);
  EXPECT_EQ(dataset.rig.left.width, truth_rig.left.width);
  EXPECT_EQ(dataset.rig.left.height, truth_rig.left.height);
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(dataset.rig.left.params[k], truth_rig.left.params[k], 1e-9) << k;
  }
  EXPECT_LT((dataset.rig.right_from_left.translation - Eigen::Vector3d(-0.54, 0, 0)).norm(), 1e-9);
  EXPECT_LT(dataset.rig.right_from_left.rotation.angularDistance(Eigen::Quaterniond::Identity()),
            1e-12);
  const colmap::Rigid3d reference = ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  const colmap::Rigid3d truth = sim::TrueCamFromLidar();
  EXPECT_LT(reference.rotation.angularDistance(truth.rotation), 1e-9);
  EXPECT_LT((reference.translation - truth.translation).norm(), 1e-9);
  // The drive's OXTS packets give the reference trajectory: each motion between frames as the
  // simulator's truth has it (the world is the first frame's IMU, so only motions compare).
  ASSERT_TRUE(dataset.HasGroundTruth());
  EXPECT_TRUE(dataset.HasReferenceExtrinsic());
  const auto reference_poses = ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt"));
  const auto true_poses = ReadNamedPoses(dir_->File("kitti/ground_truth/cam_from_world.txt"));
  ASSERT_EQ(reference_poses.size(), 5u);
  for (size_t i = 1; i < dataset.stations.size(); ++i) {
    const auto motion = [&](const std::map<std::string, colmap::Rigid3d>& poses) {
      return poses.at(dataset.stations[i]) * colmap::Inverse(poses.at(dataset.stations[0]));
    };
    EXPECT_LT((motion(reference_poses).translation - motion(true_poses).translation).norm(), 1e-6);
    EXPECT_LT(motion(reference_poses).rotation.angularDistance(motion(true_poses).rotation), 1e-8);
  }
  // The frames' and sweeps' timestamps: 0.1 s apart, each sweep 0.05 s either side of its frame.
  ASSERT_EQ(dataset.frame_times.size(), 5u);
  ASSERT_EQ(dataset.sweep_times.size(), 5u);
  EXPECT_NEAR(dataset.frame_times[3] - dataset.frame_times[0], 0.3, 1e-6);
  EXPECT_NEAR(dataset.sweep_times[2].first, dataset.frame_times[2] - 0.05, 1e-6);
  EXPECT_NEAR(dataset.sweep_times[2].second, dataset.frame_times[2] + 0.05, 1e-6);
  EXPECT_TRUE(dataset.rig.IsMovingPlatform());
  // The clouds are KITTI's .bin, read as they are.
  EXPECT_EQ(fs::path(dataset.cloud_paths[2]).extension(), ".bin");
  EXPECT_GT(ReadPointCloud(dataset.cloud_paths[2]).Size(), 10000u);
}

TEST_F(KittiImportTest, SelectsFramesCamerasAndWritesASeededGuess) {
  auto run = Import(dir_->File("selected"), "--first 1 --step 2 --use_right 0 --write_guess 1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const StationDataset selected = ReadStationDataset(dir_->File("selected"));
  EXPECT_EQ(selected.stations, (std::vector<std::string>{"0000000001", "0000000003"}));
  EXPECT_FALSE(selected.rig.IsStereo());
  ASSERT_TRUE(selected.rig.cam_from_lidar_guess);
  EXPECT_NEAR(selected.rig.cam_from_lidar_guess->rotation.angularDistance(
                  sim::TrueCamFromLidar().rotation) *
                  180 / M_PI,
              3.0,
              1e-6);
  run = Import(dir_->File("selected_again"), "--first 1 --step 2 --use_right 0 --write_guess 1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto again = ReadStationDataset(dir_->File("selected_again")).rig.cam_from_lidar_guess;
  EXPECT_EQ(again->translation, selected.rig.cam_from_lidar_guess->translation);
  // An existing output is kept without --overwrite.
  run = Import(dir_->File("selected"), "");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("--overwrite"), std::string::npos) << run.output;
}

// A copy of the drive to break.
std::string CopyOf(const std::string& from, const std::string& to) {
  fs::copy(from, to, fs::copy_options::recursive);
  return to;
}

void ExpectRefused(const testing::CommandResult& run,
                   const std::string& file,
                   const std::string& problem,
                   const std::string& output) {
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("ERROR:"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(file), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(problem), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(output)) << output;
  EXPECT_FALSE(fs::exists(output + ".partial")) << output;
}

TEST_F(KittiImportTest, BadDrivesAreRefusedNamingTheFile) {
  // No P_rect_02 in the calibration.
  const std::string calib = CopyOf(Calib(), dir_->File("bad_calib"));
  {
    std::ifstream in(calib + "/calib_cam_to_cam.txt");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(calib + "/calib_cam_to_cam.txt")
        << std::regex_replace(text, std::regex("P_rect_02:[^\n]*\n"), "");
  }
  ExpectRefused(Import(dir_->File("out1"), "", Drive(), calib),
                "calib_cam_to_cam.txt",
                "P_rect_02",
                dir_->File("out1"));

  // A frame without its cloud, then a truncated cloud.
  const std::string drive = CopyOf(Drive(), dir_->File("bad_drive"));
  const std::string cloud = drive + "/velodyne_points/data/0000000003.bin";
  fs::rename(cloud, cloud + ".moved");
  ExpectRefused(Import(dir_->File("out2"), "", drive),
                "0000000003.bin",
                "no Velodyne cloud",
                dir_->File("out2"));
  fs::rename(cloud + ".moved", cloud);
  fs::resize_file(cloud, fs::file_size(cloud) - 5);
  ExpectRefused(
      Import(dir_->File("out3"), "", drive), "0000000003.bin", "truncated", dir_->File("out3"));
}

// Replaces the first match of `pattern` in the text file at `path`.
void Edit(const std::string& path, const std::string& pattern, const std::string& replacement) {
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(path) << std::regex_replace(
      text, std::regex(pattern), replacement, std::regex_constants::format_first_only);
}

TEST_F(KittiImportTest, BadPacketsAndTimestampsAreRefusedNamingFileAndLine) {
  const std::string drive = CopyOf(Drive(), dir_->File("bad_oxts"));
  const std::string packet = drive + "/oxts/data/0000000002.txt";
  Edit(packet, "^[^ ]+ [^ ]+ [^ ]+", "49 8.4 nan");
  ExpectRefused(Import(dir_->File("out4"), "", drive),
                packet + ":1:",
                "'nan' is not a finite number",
                dir_->File("out4"));
  fs::remove_all(drive + "/oxts");
  const std::string starts = drive + "/velodyne_points/timestamps_start.txt";
  Edit(starts, "\n[^\n]*\n", "\n2011-09-26 13:02:20.000000000\n");
  ExpectRefused(Import(dir_->File("out5"), "", drive),
                starts + ":2:",
                "is not after the one before",
                dir_->File("out5"));
  // Without OXTS and timestamps the drive imports, saying once what it lacks.
  fs::remove(starts);
  const auto run = Import(dir_->File("out6"), "", drive);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("oxts/data is absent: no reference trajectory"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("timestamps_end.txt is absent"), std::string::npos) << run.output;
  const StationDataset dataset = ReadStationDataset(dir_->File("out6"));
  EXPECT_FALSE(dataset.HasGroundTruth());
  EXPECT_TRUE(dataset.sweep_times.empty());
  EXPECT_EQ(dataset.frame_times.size(), 5u);
}

}  // namespace
}  // namespace colmap_lidar
