// The evaluators through the CLI, on simulated data: ~0 for the truth, the known value for known errors.
#include "bridge/simulation/simulate_dataset.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/reconstruction.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace colmap_lidar {
namespace {

using testing::RunCommand;
const std::string kCli = COLMAP_LIDAR_CLI_EXE;

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream file(path);
  return nlohmann::json::parse(file);
}

class EvaluatorCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    sim::SimulateSmallDataset(dir_.File("dataset"), 4, 0.25, 5000);
    dataset_ = ReadStationDataset(dir_.File("dataset"));
  }
  testing::ScopedTempDir dir_;
  StationDataset dataset_;
};

TEST_F(EvaluatorCliTest, EvaluateModelMeasuresTruthAndAKnownOffset) {
  const std::string surface = dataset_.GroundTruthPath("surface.ply");
  auto result =
      RunCommand(kCli + " evaluate_model --model_path " + surface + " --ground_truth_path " +
                 surface + " --output_path " + dir_.File("self"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  nlohmann::json metrics = ReadJson(dir_.File("self/metrics.json"));
  EXPECT_LT(metrics["mean_m"].get<double>(), 1e-9);
  EXPECT_DOUBLE_EQ(metrics["completeness_2mm"].get<double>(), 1.0);
  EXPECT_TRUE(std::filesystem::exists(dir_.File("self/error_histogram.png")));
  EXPECT_TRUE(std::filesystem::exists(dir_.File("self/error_colored.ply")));

  // Pushed 4 mm outwards along the normals, without ICP: mean distance 4 mm, nothing within 2 mm.
  PointCloud shifted = ReadPointCloud(surface);
  for (size_t i = 0; i < shifted.Size(); ++i) shifted.points[i] += 0.004 * shifted.normals[i];
  WritePointCloud(dir_.File("shifted.ply"), shifted);
  result =
      RunCommand(kCli + " evaluate_model --align_icp 0 --model_path " + dir_.File("shifted.ply") +
                 " --ground_truth_path " + surface + " --output_path " + dir_.File("shifted"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  metrics = ReadJson(dir_.File("shifted/metrics.json"));
  EXPECT_NEAR(metrics["mean_m"].get<double>(), 0.004, 2e-4);
  EXPECT_NEAR(metrics["median_m"].get<double>(), 0.004, 1e-5);
  EXPECT_LT(metrics["precision_2mm"].get<double>(), 0.02);

  // Bad input: one clear error, non-zero exit, no output folder left behind.
  result = RunCommand(kCli + " evaluate_model --model_path " + dir_.File("missing.ply") +
                      " --ground_truth_path " + surface + " --output_path " + dir_.File("bad"));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("missing.ply"), std::string::npos) << result.output;
  result = RunCommand(kCli + " evaluate_model --thresholds_m 2mm --model_path " + surface +
                      " --ground_truth_path " + surface + " --output_path " + dir_.File("bad"));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("--thresholds_m"), std::string::npos) << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir_.File("bad")));
}

TEST_F(EvaluatorCliTest, EvaluateCalibrationMeasuresTruthAndTheGuess) {
  // A COLMAP model holding the true station poses.
  colmap::Reconstruction model;
  colmap::Camera camera = dataset_.rig.left;
  camera.camera_id = 1;
  model.AddCamera(camera);
  const auto truth = ReadNamedPoses(dataset_.GroundTruthPath("cam_from_world.txt"));
  colmap::image_t image_id = 1;
  for (size_t i = 0; i < dataset_.stations.size(); ++i) {
    colmap::Image image;
    image.SetImageId(image_id);
    image.SetCameraId(1);
    image.SetName(dataset_.LeftImageName(i));
    image.CamFromWorld() = truth.at(dataset_.stations[i]);
    model.AddImage(image);
    model.RegisterImage(image_id++);
  }
  std::filesystem::create_directories(dir_.File("sparse"));
  model.Write(dir_.File("sparse"));
  std::filesystem::copy_file(dataset_.GroundTruthPath("cam_from_lidar.txt"),
                             dir_.File("sparse/cam_from_lidar.txt"));
  auto result =
      RunCommand(kCli + " evaluate_calibration --dataset_path " + dataset_.root + " --input_path " +
                 dir_.File("sparse") + " --output_path " + dir_.File("truth"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  nlohmann::json metrics = ReadJson(dir_.File("truth/metrics.json"));
  EXPECT_LT(metrics["cam_from_lidar_rotation_error_deg"].get<double>(), 1e-6);
  EXPECT_LT(metrics["cam_from_lidar_translation_error_mm"].get<double>(), 1e-6);
  EXPECT_LT(metrics["pose_position_error_max_mm"].get<double>(), 1e-6);
  EXPECT_EQ(metrics["num_stations_evaluated"].get<int>(), 4);

  // The rig.json guess is the truth perturbed by the documented 3 deg and 50 mm.
  WritePoseFile(dir_.File("guess.txt"), "guess", *dataset_.rig.cam_from_lidar_guess);
  result = RunCommand(kCli + " evaluate_calibration --dataset_path " + dataset_.root +
                      " --input_path " + dir_.File("sparse") + " --cam_from_lidar " +
                      dir_.File("guess.txt") + " --output_path " + dir_.File("guess"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  metrics = ReadJson(dir_.File("guess/metrics.json"));
  EXPECT_NEAR(metrics["cam_from_lidar_rotation_error_deg"].get<double>(), 3.0, 1e-6);
  EXPECT_NEAR(metrics["cam_from_lidar_translation_error_mm"].get<double>(), 50.0, 1e-6);

  result = RunCommand(kCli + " evaluate_calibration --dataset_path " + dataset_.root +
                      " --input_path " + dir_.File("no_model"));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("no_model"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace colmap_lidar
