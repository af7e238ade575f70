// The pipeline end to end through the CLI, without a cam_from_lidar guess: import, stereo depth,
// depth priors, LiDAR registration, initialisation (hand-eye), joint adjustment, dense model,
// evaluation; stopped after a step and continued; restartable; options reach the steps. The
// default scene's workspace is the fixture of the dense and COLMAP-workflow tests
// (pipeline_dense_test.cc).
#include "colmap_ext/station_dataset.h"
#include "tests/testing/pipeline_fixture.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/database.h"
#include "colmap/scene/reconstruction.h"

#include <gtest/gtest.h>

#include <functional>
#include <map>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::kCli;
using testing::ReadJson;
using testing::RunCommand;

// Connected components of the image graph (pairs with at least `min_inliers` verified matches).
int ImageGraphComponents(const std::string& database_path, int min_inliers) {
  const colmap::Database database(database_path);
  std::map<colmap::image_t, colmap::image_t> parent;
  for (const colmap::Image& image : database.ReadAllImages()) {
    parent[image.ImageId()] = image.ImageId();
  }
  std::function<colmap::image_t(colmap::image_t)> find = [&](colmap::image_t i) {
    return parent[i] == i ? i : parent[i] = find(parent[i]);
  };
  std::vector<std::pair<colmap::image_t, colmap::image_t>> pairs;
  std::vector<int> num_inliers;
  database.ReadTwoViewGeometryNumInliers(&pairs, &num_inliers);
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (num_inliers[k] >= min_inliers) parent[find(pairs[k].first)] = find(pairs[k].second);
  }
  int components = 0;
  for (const auto& [image, p] : parent) components += find(image) == image;
  return components;
}

TEST(PipelineTest, DefaultSceneWithoutAGuessEndToEndAndRestartable) {
  const testing::PipelineFixture f;
  fs::remove_all(f.root);
  fs::create_directories(f.root);
  const std::string dataset = testing::Simulate(f.dataset, "t_specimen", 8, 1.0, 300000, false);
  ASSERT_FALSE(ReadStationDataset(dataset).rig.cam_from_lidar_guess);
  // A step's option given to the pipeline reaches the step.
  const std::string command = kCli + " pipeline --dataset_path " + dataset + " --workspace_path " +
                              f.ws + " --JointAdjuster.write_text 1";
  // Up to the initial model, then the rest on the same workspace.
  const auto initial = RunCommand(command + " --stop_after pose_initializer");
  ASSERT_EQ(initial.exit_code, 0) << initial.output;
  EXPECT_NE(initial.output.find("stopped after pose_initializer"), std::string::npos);
  EXPECT_TRUE(fs::is_regular_file(f.File("sparse/initial/images.bin")));
  EXPECT_FALSE(fs::exists(f.File("sparse/joint")));
  const auto run = RunCommand(command);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::cout << run.output.substr(run.output.find("== Pipeline summary")) << std::endl;
  EXPECT_TRUE(fs::is_regular_file(f.File("sparse/joint/images.txt")));
  EXPECT_FALSE(fs::exists(f.File("sparse/initial/images.txt")));
  const nlohmann::json init = ReadJson(f.File("sparse/initial/initialization.json"));
  // The hand-eye's start, refined by the stereo-LiDAR alignment.
  EXPECT_EQ(init["extrinsic_source"], "hand-eye + stereo-LiDAR alignment");
  EXPECT_TRUE(init["stereo_alignment"]["used"].get<bool>());
  EXPECT_TRUE(init["hand_eye"]["unique"].get<bool>());
  const nlohmann::json metrics = ReadJson(f.File("evaluation/metrics.json"));
  std::cout << "pipeline without a guess: cam_from_lidar error "
            << metrics["cam_from_lidar_rotation_error_deg"] << " deg, "
            << metrics["cam_from_lidar_translation_error_mm"] << " mm; poses mean "
            << metrics["pose_position_error_mean_mm"] << " mm" << std::endl;
  EXPECT_EQ(metrics["num_stations_evaluated"].get<int>(), 8);
  EXPECT_LE(metrics["cam_from_lidar_rotation_error_deg"].get<double>(), 0.05);
  // 8 stations, not the default 25: the translation bound is a regression bound (measured 1.4-3.1 mm;
  // the 25-station demo gives 0.9 mm). The reported covariance is NOT checked here: on these 8
  // stations its vertical (camera y) sigma, 0.75 mm, is about 2x too small (error 2.9 mm): a known
  // defect of the uncertainty estimate with only two tilted stations.
  EXPECT_LE(metrics["cam_from_lidar_translation_error_mm"].get<double>(), 5.0);
  EXPECT_LE(metrics["pose_position_error_mean_mm"].get<double>(), 2.0);
  // The dense model's accuracy is checked against the unrefined stereo in pipeline_dense_test.cc.
  const nlohmann::json dense = ReadJson(f.File("evaluation/model/metrics.json"));
  EXPECT_LT(dense["mean_m"].get<double>(), 0.0025);
  // The dense depth maps against the true ones (evaluate_dense_depth), the background included.
  // Measured in two runs: depth on 54 / 56 % of the pixels, median error 2.6 / 6.1 mm, 97 / 74 %
  // within 5 cm (the second run's stations 6 and 7 at 21-27 mm).
  const nlohmann::json depth = ReadJson(f.File("evaluation/dense_depth/metrics.json"))["all"];
  std::cout << "dense depth: coverage " << depth["coverage"] << ", median error "
            << depth["median_abs_error_m"] << " m, within 5 cm " << depth["within_5cm"]
            << std::endl;
  EXPECT_GT(depth["coverage"].get<double>(), 0.4);
  EXPECT_LT(depth["median_abs_error_m"].get<double>(), 0.018);
  EXPECT_GT(depth["within_5cm"].get<double>(), 0.6);

  // A second run finds every step done.
  const auto again = RunCommand(command);
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(again.output.find(" ran "), std::string::npos) << again.output;
  // The summary's row of the joint adjuster says skipped (its columns are padded to the names).
  const size_t row = again.output.find("\n  joint_adjuster ");
  ASSERT_NE(row, std::string::npos) << again.output;
  const std::string joint_row =
      again.output.substr(row + 1, again.output.find('\n', row + 1) - row - 1);
  EXPECT_NE(joint_row.find(" skipped "), std::string::npos) << joint_row;
}

// Few stations around a square pillar: the image graph falls apart, LiDAR edges hold it together.
// Hand-eye needs image and LiDAR edges on the same pairs; here it cannot work, and without rig.json's
// guess the pipeline must stop saying so. With the guess every station is registered.
TEST(PipelineTest, LidarBridgesADisconnectedImageGraph) {
  testing::ScopedTempDir dir;
  const std::string dataset =
      testing::Simulate(dir.File("dataset"), "square_pillar", 5, 0.6, 200000, true);
  const StationDataset with_guess = ReadStationDataset(dataset);
  StationRig rig = with_guess.rig;
  rig.cam_from_lidar_guess.reset();
  WriteRigJson(dataset + "/rig.json", rig);
  const auto refused = RunCommand(kCli + " pipeline --dataset_path " + dataset +
                                  " --workspace_path " + dir.File("ws"));
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("degenerate motion for hand-eye calibration"), std::string::npos)
      << refused.output;
  EXPECT_NE(refused.output.find("add cam_from_lidar_guess"), std::string::npos);
  WriteRigJson(dataset + "/rig.json",
               with_guess.rig);  // the finished steps are kept
  // Options from an .ini file, COLMAP-style: [Section] key=value reaches the step.
  std::ofstream(dir.File("project.ini"))
      << "dataset_path=" << dataset << "\nworkspace_path=" << dir.File("ws")
      << "\n[JointAdjuster]\nwrite_text=1\n";
  const auto run = RunCommand(kCli + " pipeline --project_path " + dir.File("project.ini"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(fs::is_regular_file(dir.File("ws/sparse/joint/points3D.txt")));
  const int components = ImageGraphComponents(dir.File("ws/database.db"), 20);
  std::cout << "image graph: " << components << " components" << std::endl;
  EXPECT_GT(components, 1) << "the case needs a disconnected image graph";
  colmap::Reconstruction reconstruction;
  reconstruction.Read(dir.File("ws/sparse/joint"));
  EXPECT_EQ(reconstruction.NumRegImages(), 5u);
  // No image landmark joins the stations here: the report must say that cam_from_lidar is not
  // calibrated rather than pretend.
  const nlohmann::json report = ReadJson(dir.File("ws/sparse/joint/report.json"));
  const std::string verdict = report["observability_verdict"];
  std::cout << "square pillar verdict: " << verdict << std::endl;
  EXPECT_NE(verdict.find("cam_from_lidar cannot be calibrated: no image landmark"),
            std::string::npos)
      << verdict;
}

}  // namespace
}  // namespace colmap_lidar
