// The joint problem end to end on simulated stations, through the CLI: simulate -> stereo_depth ->
// import_dataset -> depth_prior_extractor -> an initial model (true poses perturbed, landmarks
// triangulated by the real `colmap point_triangulator`) -> joint_adjuster; accuracy against ground truth.
#include "bridge/evaluation/calibration_evaluation.h"
#include "bridge/simulation/simulate_dataset.h"
#include "colmap_ext/station_dataset.h"
#include "tests/testing/file_bytes.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/feature/utils.h"
#include "colmap/scene/database.h"
#include "colmap/scene/reconstruction.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::FileBytes;
using testing::RunCommand;
using testing::RunStep;

const std::string kCli = COLMAP_LIDAR_CLI_EXE;
const std::string kColmap = COLMAP_LIDAR_COLMAP_EXE;

colmap::Rigid3d Perturb(const colmap::Rigid3d& pose,
                        double angle_deg,
                        double distance_m,
                        std::mt19937* rng) {
  std::normal_distribution<double> normal(0, 1);
  const Eigen::Vector3d axis =
      Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng)).normalized();
  const Eigen::Vector3d direction =
      Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng)).normalized();
  return colmap::Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(angle_deg * M_PI / 180, axis)) * pose.rotation,
      pose.translation + distance_m * direction);
}

// A station dataset taken through the front end, with an initial sparse model.
struct Workspace {
  std::string dataset;
  std::string database;
  std::string initial_model;  // true poses perturbed, landmarks from colmap point_triangulator
  std::string guess;          // cam_from_lidar perturbed by 5 deg and 10 cm
};

Workspace Prepare(const testing::ScopedTempDir& dir,
                  const sim::SimulationOptions& simulation,
                  double pose_noise_deg,
                  double pose_noise_m) {
  Workspace ws;
  sim::SimulationOptions options = simulation;
  options.output_path = dir.File("dataset");
  sim::SimulateDataset(options);
  ws.dataset = options.output_path;
  ws.database = dir.File("db.db");
  for (const std::string& command :
       {kCli + " stereo_depth --dataset_path " + ws.dataset + " --output_path " +
            dir.File("stereo"),
        kCli + " import_dataset --dataset_path " + ws.dataset + " --database_path " + ws.database +
            " --SiftExtraction.num_threads 2 --SiftMatching.num_threads 2",
        kCli + " depth_prior_extractor --database_path " + ws.database + " --depth_path " +
            dir.File("stereo")}) {
    RunStep(command);
  }

  // The initial model: COLMAP's images with the true poses, perturbed (the first one exact: the gauge).
  const StationDataset dataset = ReadStationDataset(ws.dataset);
  const auto truth = ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt"));
  std::mt19937 rng(7);
  colmap::Reconstruction reconstruction;
  {
    const colmap::Database database(ws.database);
    for (const colmap::Camera& camera : database.ReadAllCameras()) {
      reconstruction.AddCamera(camera);
    }
    std::vector<colmap::Image> images = database.ReadAllImages();
    std::sort(images.begin(), images.end(), [](const auto& a, const auto& b) {
      return a.Name() < b.Name();
    });
    for (size_t i = 0; i < images.size(); ++i) {
      colmap::Image image = images[i];
      const colmap::Rigid3d& pose = truth.at(StationOfImageName(image.Name()));
      image.CamFromWorld() = i == 0 ? pose : Perturb(pose, pose_noise_deg, pose_noise_m, &rng);
      image.SetPoints2D(
          colmap::FeatureKeypointsToPointsVector(database.ReadKeypoints(image.ImageId())));
      reconstruction.AddImage(image);
      reconstruction.RegisterImage(image.ImageId());
    }
  }
  fs::create_directories(dir.File("initial"));
  fs::create_directories(dir.File("triangulated"));
  reconstruction.Write(dir.File("initial"));
  RunStep(kColmap + " point_triangulator --database_path " + ws.database + " --image_path " +
          ws.dataset + "/images --input_path " + dir.File("initial") + " --output_path " +
          dir.File("triangulated") + " --Mapper.num_threads 2");
  ws.initial_model = dir.File("triangulated");

  const colmap::Rigid3d true_cam_from_lidar =
      ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  const colmap::Rigid3d guess = Perturb(true_cam_from_lidar, 5.0, 0.10, &rng);
  ws.guess = dir.File("guess.txt");
  WritePoseFile(ws.guess, "5 deg / 10 cm off", guess);
  return ws;
}

struct JointResult {
  CalibrationEvaluation evaluation;
  nlohmann::json report;
  std::string output;
};

JointResult RunJoint(const Workspace& ws, const std::string& output, const std::string& arguments) {
  JointResult result;
  const auto run = RunStep(kCli + " joint_adjuster --database_path " + ws.database +
                           " --input_path " + ws.initial_model + " --dataset_path " + ws.dataset +
                           " --output_path " + output + " " + arguments);
  result.output = run.output;
  std::ifstream report(output + "/report.json");
  result.report = nlohmann::json::parse(report);
  const StationDataset dataset = ReadStationDataset(ws.dataset);
  colmap::Reconstruction reconstruction;
  reconstruction.Read(output);
  result.evaluation =
      EvaluateCalibration(ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt")),
                          ReadPoseFile(output + "/cam_from_lidar.txt"),
                          ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt")),
                          reconstruction,
                          TrajectoryAlignment::kRigid);
  std::cout << output << ": cam_from_lidar error "
            << result.evaluation.cam_from_lidar_rotation_error_deg << " deg, "
            << result.evaluation.cam_from_lidar_translation_error_mm << " mm (in camera: "
            << result.evaluation.cam_from_lidar_translation_error_in_cam_mm.transpose()
            << "); poses mean " << result.evaluation.mean_position_error_mm << " mm, max "
            << result.evaluation.max_position_error_mm << " mm, rotation mean "
            << result.evaluation.mean_rotation_error_deg << " deg" << std::endl;
  return result;
}

sim::SimulationOptions Stations(int num_stations, sim::Motion motion) {
  sim::SimulationOptions options;
  options.num_stations = num_stations;
  options.motion = motion;
  options.lidar_points = 300000;
  return options;
}

TEST(JointAdjusterTest, DefaultSceneWithNoise) {
  testing::ScopedTempDir dir;
  const Workspace ws = Prepare(dir, Stations(10, sim::Motion::kTwoAxes), 0.3, 0.01);
  const JointResult joint = RunJoint(ws, dir.File("joint"), "--cam_from_lidar " + ws.guess);
  std::cout << joint.output.substr(joint.output.find("Round 1/")) << std::endl;
  const JointResult precalibrated =
      RunJoint(ws, dir.File("precalibrated"), "--mode precalibrated --cam_from_lidar " + ws.guess);
  const JointResult stereo_only =
      RunJoint(ws, dir.File("stereo_only"), "--mode stereo_only --cam_from_lidar " + ws.guess);

  // Measured: 0.010 deg, 0.62 mm, positions 0.48 mm mean; bounds 2-3x.
  EXPECT_LE(joint.evaluation.cam_from_lidar_rotation_error_deg, 0.02);
  EXPECT_LE(joint.evaluation.cam_from_lidar_translation_error_mm, 2.0);
  EXPECT_LE(joint.evaluation.mean_position_error_mm, 1.2);
  // Within 4 reported sigma per camera axis. One run cannot test 2-sigma coverage (that is
  // scripts/benchmark_uncertainty.sh's job); end to end the vertical axis was seen at 2.4-3.4 sigma.
  const auto& sigma = joint.report["uncertainty"]["sigma_translation_mm"];
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LE(std::abs(joint.evaluation.cam_from_lidar_translation_error_in_cam_mm[axis]),
              4 * sigma[axis].get<double>())
        << "axis " << axis;
  }
  EXPECT_LT(joint.evaluation.mean_position_error_mm,
            precalibrated.evaluation.mean_position_error_mm);
  EXPECT_LT(joint.evaluation.mean_position_error_mm, stereo_only.evaluation.mean_position_error_mm);
  // Each data term's pull, and no disagreement between them: the simulation has no sensor model
  // error.
  EXPECT_EQ(joint.report["uncertainty"]["term_pulls"].size(), 4u);
  EXPECT_TRUE(joint.report["uncertainty"]["term_disagreements"].empty())
      << joint.report["uncertainty"]["term_pulls"].dump(1);
  EXPECT_TRUE(fs::exists(dir.File("joint/perturbation_rotation.png")));
  EXPECT_TRUE(fs::exists(dir.File("joint/cost.png")));
  // The curves per term: the total less E_l, E_m and E_x is the rest, which does not depend on
  // cam_from_lidar; E_l grows away from the optimum along every parameter.
  for (const nlohmann::json& curve : joint.report["perturbation"]) {
    const auto& costs = curve["costs"];
    const auto rest = [&](size_t k) {
      return costs[k].get<double>() - curve["lidar_costs"][k].get<double>() -
             curve["landmark_lidar_costs"][k].get<double>() -
             curve["extrinsic_costs"][k].get<double>();
    };
    const size_t middle = costs.size() / 2;
    for (size_t k = 0; k < costs.size(); ++k) {
      EXPECT_NEAR(rest(k), rest(0), 1e-6 * costs[k].get<double>()) << curve["parameter"];
    }
    EXPECT_GT(curve["lidar_costs"][0].get<double>(), curve["lidar_costs"][middle].get<double>());
    EXPECT_GT(curve["lidar_costs"][costs.size() - 1].get<double>(),
              curve["lidar_costs"][middle].get<double>());
  }
}

// Results do not depend on the thread count: OpenMP's (associations) and Ceres' (the solves).
TEST(JointAdjusterTest, SameOutputWithOneAndFourThreads) {
  testing::ScopedTempDir dir;
  sim::SimulationOptions options = Stations(10, sim::Motion::kOneAxis);
  options.image_scale = 0.6;
  const Workspace ws = Prepare(dir, options, 0.3, 0.01);
  for (const char* threads : {"1", "4"}) {
    RunStep(std::string("OMP_NUM_THREADS=") + threads + " " + kCli +
            " joint_adjuster --database_path " + ws.database + " --input_path " + ws.initial_model +
            " --dataset_path " + ws.dataset + " --output_path " +
            dir.File(std::string("joint") + threads) + " --cam_from_lidar " + ws.guess);
  }
  for (const char* file : {"cam_from_lidar.txt", "images.bin", "points3D.bin"}) {
    const std::string one = FileBytes(dir.File("joint1/") + file);
    EXPECT_FALSE(one.empty()) << file;
    EXPECT_TRUE(one == FileBytes(dir.File("joint4/") + file)) << file << " differs";
  }
}

// Degenerate motion: the report names what cannot be observed.
TEST(JointAdjusterTest, OneAxisMotionLeavesTranslationAlongTheAxisUnobservable) {
  testing::ScopedTempDir dir;
  sim::SimulationOptions options = Stations(10, sim::Motion::kOneAxis);
  options.image_scale = 0.6;
  const Workspace ws = Prepare(dir, options, 0.3, 0.01);
  // A given hold threshold is the one used (a start from the guess once overrode it).
  const JointResult joint =
      RunJoint(ws, dir.File("joint"), "--cam_from_lidar " + ws.guess + " --hold_translation_mm 30");
  EXPECT_EQ(joint.report["hold_thresholds"]["translation_mm"].get<double>(), 30);
  const std::string verdict = joint.report["observability_verdict"];
  std::cout << "verdict: " << verdict << std::endl;
  EXPECT_NE(verdict.find("translation along the camera y axis is unobservable"), std::string::npos)
      << joint.report["unobservable"].dump();
  EXPECT_NE(verdict.find("rotate about one axis"), std::string::npos) << verdict;
  EXPECT_FALSE(joint.report["motion"]["unique"].get<bool>());
}

// Stations that do not rotate: the paper's cost cannot observe any translation of T_e, and tripod
// stations keep the paper's cost by default (the landmark-to-LiDAR-plane term is automatic only on
// a moving platform; on these stations it once ended 128 mm off with a reported sigma of 7 mm).
TEST(JointAdjusterTest, FixedRotationLeavesAllTranslationUnobservable) {
  testing::ScopedTempDir dir;
  sim::SimulationOptions options = Stations(4, sim::Motion::kFixedRotation);
  options.image_scale = 0.6;
  const Workspace ws = Prepare(dir, options, 0.3, 0.01);
  const JointResult joint = RunJoint(ws, dir.File("joint"), "--cam_from_lidar " + ws.guess);
  EXPECT_EQ(joint.report["landmark_lidar_weight"].get<double>(), 0.0);
  const std::string verdict = joint.report["observability_verdict"];
  std::cout << "verdict: " << verdict << std::endl;
  EXPECT_NE(verdict.find("all translation of cam_from_lidar is unobservable"), std::string::npos)
      << joint.report["unobservable"].dump();
  EXPECT_NE(verdict.find("do not rotate"), std::string::npos) << verdict;
}

}  // namespace
}  // namespace colmap_lidar
