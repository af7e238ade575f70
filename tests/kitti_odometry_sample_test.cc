// The real KITTI odometry sample in ../shared/data (sequence 04, frames 0-19; not part of the
// repository; the tests skip without it): import_kitti --format odometry in stereo and mono with the
// benchmark's reference poses, its bad inputs, and evaluate_trajectory against an independent
// computation (scripts/kitti_relative_error.py, plain Python), LiDAR odometry, the pose initialiser
// on a straight drive without a guess, and the joint adjuster's report of the sensors' disagreement.
#include "colmap_ext/kitti_calibration.h"
#include "colmap_ext/station_dataset.h"
#include "colmap_ext/trajectory_files.h"
#include "tests/testing/distorted_trajectory.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;

const std::string kCli = COLMAP_LIDAR_CLI_EXE;
const std::string kSequence = std::string(COLMAP_LIDAR_SHARED_DATA) + "/kitti_odometry_04_sample";
const std::string kPoses = kSequence + "/poses/04.txt";

testing::CommandResult Import(const std::string& sequence,
                              const std::string& output,
                              const std::string& arguments) {
  return RunCommand(kCli + " import_kitti --format odometry --sequence_path " + sequence +
                    " --output_path " + output + " " + arguments);
}

Eigen::Matrix<double, 3, 4> CalibMatrix(const std::string& key) {
  const auto calib = ReadKittiCalibFile(kSequence + "/calib.txt");
  return Eigen::Matrix<double, 3, 4, Eigen::RowMajor>(calib.at(key).data());
}

// [I | K^-1 P[:,3]] * Tr as a 3x4 matrix, from the file's numbers.
Eigen::Matrix<double, 3, 4> HandReference() {
  const Eigen::Matrix<double, 3, 4> p2 = CalibMatrix("P2"), tr = CalibMatrix("Tr");
  const Eigen::Vector3d offset = p2.leftCols<3>().inverse() * p2.col(3);
  Eigen::Matrix<double, 3, 4> reference = tr;
  reference.col(3) += offset;
  return reference;
}

class KittiOdometrySampleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::is_directory(kSequence)) GTEST_SKIP() << "no KITTI odometry sample at " << kSequence;
  }
  testing::ScopedTempDir dir_{"colmap_lidar_kitti_odometry"};
};

TEST_F(KittiOdometrySampleTest, ImportsTheStereoSequenceWithItsReferences) {
  const auto run = Import(kSequence, dir_.File("stereo"), "--poses_path " + kPoses);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const StationDataset dataset = ReadStationDataset(dir_.File("stereo"));
  ASSERT_EQ(dataset.stations.size(), 20u);
  EXPECT_EQ(dataset.stations.front(), "000000");
  ASSERT_TRUE(dataset.rig.IsStereo());
  EXPECT_EQ(dataset.rig.left.width, 1226u);
  EXPECT_EQ(dataset.rig.left.height, 370u);
  EXPECT_NEAR(dataset.rig.BaselineMeters(), 0.532, 0.01);
  // Already motion-compensated scans: a moving platform, nothing to de-skew.
  EXPECT_FALSE(dataset.rig.lidar_sweep);
  EXPECT_TRUE(dataset.rig.IsMovingPlatform());
  // The reference extrinsic is [I | K^-1 P2[:,3]] Tr: its translation exactly; its rotation within
  // the distance of Tr's printed 3x3 block from a rotation.
  const Eigen::Matrix<double, 3, 4> hand = HandReference();
  const colmap::Rigid3d reference = ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  EXPECT_LT((reference.translation - hand.col(3)).norm(), 1e-12);
  const Eigen::Matrix3d r = hand.leftCols<3>();
  const double orthonormality = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm();
  EXPECT_LT((reference.rotation.toRotationMatrix() - r).norm(), 2 * orthonormality + 1e-12);
  // Reference poses: camera 2 from the benchmark's world_from_cam0, frame by frame.
  const auto cam_from_world = ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt"));
  const std::vector<colmap::Rigid3d> world_from_cam0 = ReadKittiPoses(kPoses);
  const colmap::Rigid3d cam2_from_cam0(Eigen::Quaterniond::Identity(),
                                       hand.col(3) - CalibMatrix("Tr").col(3));
  for (size_t k = 0; k < 20; ++k) {
    const colmap::Rigid3d expected = cam2_from_cam0 * colmap::Inverse(world_from_cam0[k]);
    const colmap::Rigid3d& pose = cam_from_world.at(dataset.stations[k]);
    EXPECT_LT((pose.translation - expected.translation).norm(), 1e-9) << k;
    EXPECT_LT(pose.rotation.angularDistance(expected.rotation), 1e-9) << k;
  }
  const std::vector<double> times = ReadKittiTimes(kSequence + "/times.txt");
  ASSERT_EQ(dataset.frame_times.size(), 20u);
  EXPECT_NEAR(dataset.frame_times[19], times[19], 1e-9);
  EXPECT_TRUE(dataset.sweep_times.empty());
}

TEST_F(KittiOdometrySampleTest, ImportsMonoAndSaysWhatIsMissing) {
  auto run = Import(kSequence, dir_.File("mono"), "--use_right 0 --first 4 --step 3");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("no --poses_path: no reference trajectory"), std::string::npos);
  const StationDataset mono = ReadStationDataset(dir_.File("mono"));
  EXPECT_FALSE(mono.rig.IsStereo());
  EXPECT_EQ(mono.stations,
            (std::vector<std::string>{"000004", "000007", "000010", "000013", "000016", "000019"}));
  EXPECT_FALSE(mono.HasGroundTruth());
  // The grey pair is not in the sample.
  run = Import(kSequence, dir_.File("grey"), "--camera 0");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("image_0 does not exist"), std::string::npos) << run.output;
}

// A sequence folder that links the sample's images and sweeps, with its own calib.txt.
std::string LinkedSequence(const testing::ScopedTempDir& dir, const std::string& calib_text) {
  const fs::path sequence = dir.Path() / "sequence";
  fs::create_directories(sequence);
  for (const char* folder : {"image_2", "image_3", "velodyne"}) {
    fs::create_directory_symlink(fs::path(kSequence) / folder, sequence / folder);
  }
  fs::copy_file(kSequence + "/times.txt", sequence / "times.txt");
  std::ofstream((sequence / "calib.txt").string()) << calib_text;
  return sequence.string();
}

void ExpectRefused(const testing::CommandResult& run,
                   const std::string& message,
                   const std::string& output) {
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("ERROR:"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(message), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(output)) << output;
  EXPECT_FALSE(fs::exists(output + ".partial")) << output;
}

TEST_F(KittiOdometrySampleTest, BadSequencesAreRefusedNamingFileAndLine) {
  std::ifstream in(kSequence + "/calib.txt");
  const std::string calib((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string sequence =
      LinkedSequence(dir_, std::regex_replace(calib, std::regex("Tr:[^\n]*\n?"), ""));
  ExpectRefused(
      Import(sequence, dir_.File("out1"), ""), sequence + "/calib.txt: no Tr", dir_.File("out1"));
  std::ofstream(sequence + "/calib.txt") << calib;
  // Ten reference poses for twenty frames.
  const std::string poses = dir_.File("short_poses.txt");
  {
    std::ifstream full(kPoses);
    std::ofstream cut(poses);
    std::string line;
    for (int k = 0; k < 10 && std::getline(full, line); ++k) cut << line << "\n";
  }
  ExpectRefused(Import(sequence, dir_.File("out2"), "--poses_path " + poses),
                poses + ":10: the file ends after 10 poses, but frame 19 needs one",
                dir_.File("out2"));
  // Times out of order.
  std::ofstream(sequence + "/times.txt") << "0.0\n0.2\n0.1\n";
  ExpectRefused(Import(sequence, dir_.File("out3"), ""),
                sequence + "/times.txt:3: time 0.100000000 is not after the one before",
                dir_.File("out3"));
}

// The reference drive with a 1 % scale error and a yaw drift of 0.01 deg/m, as a KITTI file (the
// camera frame's y points down: the yaw is about y).
void WriteDistortedEstimate(const std::string& path) {
  WriteKittiPoses(
      path,
      testing::DistortedTrajectory(ReadKittiPoses(kPoses), 1.01, 0.01, Eigen::Vector3d::UnitY()));
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream file(path);
  return nlohmann::json::parse(file);
}

TEST_F(KittiOdometrySampleTest, EvaluateTrajectoryAgreesWithAnIndependentComputation) {
  const std::string estimate = dir_.File("estimate.txt");
  WriteDistortedEstimate(estimate);
  const auto run =
      RunCommand(kCli + " evaluate_trajectory --trajectory_path " + estimate +
                 " --reference_path " + kPoses + " --output_path " + dir_.File("evaluation"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("relative error"), std::string::npos) << run.output;
  for (const char* file : {"metrics.json", "top_view.png", "step_errors.png"}) {
    EXPECT_TRUE(fs::is_regular_file(dir_.File("evaluation/") + file)) << file;
  }
  const nlohmann::json ours = ReadJson(dir_.File("evaluation/metrics.json"));
  const auto python = RunCommand("python3 " + std::string(COLMAP_LIDAR_SOURCE_DIR) +
                                 "/scripts/kitti_relative_error.py " + estimate + " " + kPoses +
                                 " > " + dir_.File("python.json"));
  ASSERT_EQ(python.exit_code, 0) << python.output;
  const nlohmann::json independent = ReadJson(dir_.File("python.json"));
  // The 25 m drive: segments of 10 and 20 m.
  ASSERT_EQ(ours["relative"]["per_length"].size(), 2u);
  EXPECT_EQ(ours["relative"]["num_segments"], independent["num_segments"]);
  const double drift = ours["relative"]["translation_percent"];
  EXPECT_NEAR(drift, independent["translation_percent"].get<double>(), 0.05);
  EXPECT_NEAR(drift, 1.0, 0.15);  // the scale error and the bend of the yaw drift
  EXPECT_NEAR(ours["relative"]["rotation_deg_per_m"].get<double>(),
              independent["rotation_deg_per_m"].get<double>(),
              1e-6);
  // KITTI's metric divides by L the drift over the first frame at or past L: up to one 1.3 m step
  // more than L.
  EXPECT_GE(ours["relative"]["rotation_deg_per_m"].get<double>(), 0.01 - 1e-9);
  EXPECT_LE(ours["relative"]["rotation_deg_per_m"].get<double>(), 0.01 * (1 + 1.32 / 10));
  EXPECT_NEAR(ours["end_to_end_drift_percent"].get<double>(),
              independent["end_to_end_drift_percent"].get<double>(),
              0.05);
}

TEST_F(KittiOdometrySampleTest, EvaluateTrajectoryMatchesTumFilesByTime) {
  ASSERT_EQ(
      Import(kSequence, dir_.File("dataset"), "--use_right 0 --poses_path " + kPoses).exit_code, 0);
  Trajectory estimate;
  estimate.times = ReadKittiTimes(kSequence + "/times.txt");
  estimate.world_from_sensor = ReadKittiPoses(kPoses);
  WriteTumTrajectory(dir_.File("estimate_tum.txt"), estimate);
  const auto run = RunCommand(
      kCli + " evaluate_trajectory --trajectory_path " + dir_.File("estimate_tum.txt") +
      " --reference_path " + dir_.File("dataset/ground_truth/cam_from_world.txt") +
      " --timestamps_path " + dir_.File("dataset") + " --output_path " + dir_.File("evaluation"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("20 frames matched by time"), std::string::npos) << run.output;
  // Camera 0's poses against camera 2's: the same motions but for the 6 cm lever arm.
  const nlohmann::json metrics = ReadJson(dir_.File("evaluation/metrics.json"));
  EXPECT_LT(metrics["relative"]["translation_percent"].get<double>(), 0.01);
  // Without the times the two cannot be matched: one clear error, no output.
  const auto unmatched =
      RunCommand(kCli + " evaluate_trajectory --trajectory_path " + dir_.File("estimate_tum.txt") +
                 " --reference_path " + dir_.File("dataset/ground_truth/cam_from_world.txt") +
                 " --output_path " + dir_.File("unmatched"));
  EXPECT_NE(unmatched.exit_code, 0);
  EXPECT_NE(unmatched.output.find("cannot match"), std::string::npos) << unmatched.output;
  EXPECT_FALSE(fs::exists(dir_.File("unmatched")));
}

// LiDAR odometry on the real scans against KITTI's reference. Measured: 0.71 % / 0.009 deg/m over
// 10 and 20 m segments (the pairwise path: 0.72 % / 0.011 deg/m); bounds about 3x.
TEST_F(KittiOdometrySampleTest, OdometryFollowsTheRealDrive) {
  ASSERT_EQ(
      Import(kSequence, dir_.File("dataset"), "--use_right 0 --poses_path " + kPoses).exit_code, 0);
  const auto run = RunCommand(kCli + " lidar_registrator --method odometry --lidar_path " +
                              dir_.File("dataset/lidar") + " --output_path " + dir_.File("lidar"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("0 degenerate"), std::string::npos) << run.output;
  const auto evaluation = RunCommand(kCli + " evaluate_trajectory --trajectory_path " +
                                     dir_.File("lidar/lidar_poses.txt") + " --reference_path " +
                                     dir_.File("dataset/ground_truth/cam_from_world.txt") +
                                     " --reference_sensor_from_sensor_path " +
                                     dir_.File("dataset/ground_truth/cam_from_lidar.txt") +
                                     " --output_path " + dir_.File("evaluation"));
  ASSERT_EQ(evaluation.exit_code, 0) << evaluation.output;
  std::cout << evaluation.output;
  const nlohmann::json metrics = ReadJson(dir_.File("evaluation/metrics.json"));
  EXPECT_LT(metrics["relative"]["translation_percent"].get<double>(), 2.2);
  EXPECT_LT(metrics["relative"]["rotation_deg_per_m"].get<double>(), 0.03);
  std::ifstream table(dir_.File("lidar/odometry.csv"));
  size_t lines = 0;
  for (std::string line; std::getline(table, line);) lines += line[0] != '#';
  EXPECT_EQ(lines, 20u);
}

// A straight drive (yaw changes < 0.5 deg) gives a hand-eye no rotation; without a guess the pose
// initialiser takes cam_from_lidar's rotation from the direction of travel and the roll about it from
// the structure both sensors see, and the translation across the drive from the structure.
TEST_F(KittiOdometrySampleTest, StraightDriveInitialisesWithoutAGuess) {
  ASSERT_EQ(Import(kSequence, dir_.File("dataset"), "--use_right 0 --write_guess 0").exit_code, 0);
  const std::string dataset = dir_.File("dataset"), database = dir_.File("database.db");
  for (const std::string& step :
       {" import_dataset --matcher sequential --dataset_path " + dataset + " --database_path " +
            database,
        " lidar_registrator --method odometry --lidar_path " + dataset + "/lidar --output_path " +
            dir_.File("lidar"),
        " pose_initializer --database_path " + database + " --dataset_path " + dataset +
            " --registration_path " + dir_.File("lidar") + " --output_path " +
            dir_.File("initial")}) {
    const auto run = RunCommand(kCli + step);
    ASSERT_EQ(run.exit_code, 0) << step << "\n" << run.output;
  }
  const nlohmann::json travel =
      ReadJson(dir_.File("initial/initialization.json"))["travel_structure"];
  std::cout << travel.dump(2) << std::endl;
  EXPECT_TRUE(travel["valid"].get<bool>());
  EXPECT_GT(travel["runner_up_rms_m"].get<double>(), 1.2 * travel["roll_rms_m"].get<double>());
  const colmap::Rigid3d estimate = ReadPoseFile(dir_.File("initial/cam_from_lidar.txt"));
  const colmap::Rigid3d truth = ReadPoseFile(dir_.File("dataset/ground_truth/cam_from_lidar.txt"));
  const double rotation_deg = estimate.rotation.angularDistance(truth.rotation) * 180 / M_PI;
  const Eigen::Vector3d translation_m = estimate.translation - truth.translation;
  std::cout << "start: " << rotation_deg << " deg, " << 1000 * translation_m.transpose() << " mm"
            << std::endl;
  EXPECT_LT(rotation_deg, 0.9);
  // Across the drive (camera x and y); along it (z) the structure of noisy triangulated points
  // fixes the translation least.
  EXPECT_LT(translation_m.head<2>().norm(), 0.22);
  EXPECT_LT(std::abs(translation_m.z()), 0.6);
}

// The HDL-64's vertical beam angles are off by about 0.2 deg: the ground is a shallow cone, and the
// LiDAR pairs put each sweep pair at a pitch the cameras do not see. The joint adjuster's report says
// that the reprojections and the LiDAR pairs pull cam_from_lidar's pitch (rotation about the camera
// x axis) apart, each beyond its own noise (docs/joint_adjuster.md, "Whether the sensors' data
// agree"); the simulated scenes, which have no such error, give no such warning
// (JointAdjusterTest.DefaultSceneWithNoise).
TEST_F(KittiOdometrySampleTest, JointAdjusterSaysTheSensorsDisagreeInPitch) {
  ASSERT_EQ(Import(kSequence, dir_.File("dataset"), "--use_right 0 --write_guess 0").exit_code, 0);
  const auto run =
      RunCommand(kCli + " pipeline --dataset_path " + dir_.File("dataset") + " --workspace_path " +
                 dir_.File("ws") + " --Import.matcher sequential --stop_after joint_adjuster");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json uncertainty =
      ReadJson(dir_.File("ws/sparse/joint/report.json"))["uncertainty"];
  const std::vector<std::string> disagreements = uncertainty["term_disagreements"];
  ASSERT_FALSE(disagreements.empty()) << uncertainty["term_pulls"].dump(1);
  const auto pitch = std::find_if(disagreements.begin(), disagreements.end(), [](const auto& s) {
    return s.find("rotation about the camera x axis") != std::string::npos;
  });
  ASSERT_NE(pitch, disagreements.end()) << uncertainty["term_pulls"].dump(1);
  EXPECT_NE(pitch->find("the lidar and reprojection terms"), std::string::npos) << *pitch;
  EXPECT_NE(run.output.find("WARNING: " + *pitch), std::string::npos);
}

// The pipeline on a drive whose frames are thinned to 4 m (every third or fourth of the 13 m/s
// drive): the LiDAR steps see every sweep, the camera steps only the selected frames, joined across
// the frames left out by the trajectory's edges. Measured from the 2 deg / 5 cm guess: 0.43 deg
// (the translation along these 7 straight frames is undetermined and stays at the guess).
TEST_F(KittiOdometrySampleTest, SelectedFramesGoOnToTheCameraSteps) {
  ASSERT_EQ(
      Import(
          kSequence, dir_.File("dataset"), "--use_right 0 --write_guess 1 --poses_path " + kPoses)
          .exit_code,
      0);
  const auto run =
      RunCommand(kCli + " pipeline --dataset_path " + dir_.File("dataset") + " --workspace_path " +
                 dir_.File("ws") + " --FrameSelection.min_distance_m 4");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("select_frames: 7 of 20 frames"), std::string::npos) << run.output;
  const auto images =
      RunCommand("sqlite3 " + dir_.File("ws/database.db") + " 'SELECT COUNT(*) FROM images;'");
  EXPECT_EQ(images.output, "7\n");
  const nlohmann::json metrics = ReadJson(dir_.File("ws/evaluation/metrics.json"));
  EXPECT_EQ(metrics["num_stations_evaluated"].get<int>(), 7);
  EXPECT_LT(metrics["cam_from_lidar_rotation_error_deg"].get<double>(), 1.3);
  // Every sweep keeps its odometry pose.
  EXPECT_NE(
      run.output.find("20 frames matched by name (0 of " + dir_.File("ws/lidar/lidar_poses.txt")),
      std::string::npos)
      << run.output;
}

TEST_F(KittiOdometrySampleTest, OdometryNamesAnUnreadableScan) {
  fs::create_directories(dir_.File("lidar"));
  for (const char* frame : {"000000", "000001", "000002"}) {
    fs::copy_file(kSequence + "/velodyne/" + frame + ".bin", dir_.File("lidar/") + frame + ".bin");
  }
  {
    std::ofstream nan(dir_.File("lidar/000003.bin"), std::ios::binary);
    const float record[4] = {NAN, NAN, NAN, 0.f};
    for (int k = 0; k < 100; ++k) nan.write(reinterpret_cast<const char*>(record), sizeof(record));
  }
  const auto run = RunCommand(kCli + " lidar_registrator --method odometry --lidar_path " +
                              dir_.File("lidar") + " --output_path " + dir_.File("out"));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find(dir_.File("lidar/000003.bin")), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(dir_.File("out/lidar_poses.txt")));
}

}  // namespace
}  // namespace colmap_lidar
