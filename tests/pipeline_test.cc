// The pipeline end to end through the CLI, without a cam_from_lidar guess: import, stereo depth, depth
// priors, LiDAR registration, initialisation (hand-eye), joint adjustment, evaluation; restartable.
#include "colmap_ext/station_dataset.h"
#include "tests/simulator/simulate_dataset.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/database.h"
#include "colmap/scene/reconstruction.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <numeric>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;

const std::string kCli = COLMAP_LIDAR_CLI_EXE;
const std::string kColmap = COLMAP_LIDAR_COLMAP_EXE;

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream file(path);
  return nlohmann::json::parse(file);
}

std::string Simulate(const testing::ScopedTempDir& dir,
                     const std::string& scene,
                     int num_stations,
                     double image_scale,
                     size_t lidar_points,
                     bool write_guess) {
  sim::SimulationOptions options;
  options.output_path = dir.File("dataset");
  options.scene = scene;
  options.num_stations = num_stations;
  options.image_scale = image_scale;
  options.lidar_points = lidar_points;
  options.write_guess = write_guess;
  sim::SimulateDataset(options);
  return options.output_path;
}

// Connected components of the image graph (pairs with at least `min_inliers` verified matches).
int ImageGraphComponents(const std::string& database_path, int min_inliers) {
  const colmap::Database database(database_path);
  std::map<colmap::image_t, colmap::image_t> parent;
  for (const colmap::Image& image : database.ReadAllImages()) {
    parent[image.ImageId()] = image.ImageId();
  }
  std::function<colmap::image_t(colmap::image_t)> find =
      [&](colmap::image_t i) {
        return parent[i] == i ? i : parent[i] = find(parent[i]);
      };
  std::vector<std::pair<colmap::image_t, colmap::image_t>> pairs;
  std::vector<int> num_inliers;
  database.ReadTwoViewGeometryNumInliers(&pairs, &num_inliers);
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (num_inliers[k] >= min_inliers)
      parent[find(pairs[k].first)] = find(pairs[k].second);
  }
  int components = 0;
  for (const auto& [image, p] : parent) components += find(image) == image;
  return components;
}

TEST(PipelineTest, DefaultSceneWithoutAGuessEndToEndAndRestartable) {
  testing::ScopedTempDir dir;
  const std::string dataset =
      Simulate(dir, "t_specimen", 8, 1.0, 300000, false);
  ASSERT_FALSE(ReadStationDataset(dataset).rig.cam_from_lidar_guess);
  const std::string command = kCli + " pipeline --dataset_path " + dataset +
                              " --workspace_path " + dir.File("ws");
  const auto run = RunCommand(command);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::cout << run.output.substr(run.output.find("== Pipeline summary"))
            << std::endl;
  const nlohmann::json init =
      ReadJson(dir.File("ws/sparse/initial/initialization.json"));
  EXPECT_EQ(init["extrinsic_source"], "hand-eye");
  EXPECT_TRUE(init["hand_eye"]["unique"].get<bool>());
  const nlohmann::json metrics =
      ReadJson(dir.File("ws/evaluation/metrics.json"));
  std::cout << "pipeline without a guess: cam_from_lidar error "
            << metrics["cam_from_lidar_rotation_error_deg"] << " deg, "
            << metrics["cam_from_lidar_translation_error_mm"]
            << " mm; poses mean " << metrics["pose_position_error_mean_mm"]
            << " mm" << std::endl;
  EXPECT_EQ(metrics["num_stations_evaluated"].get<int>(), 8);
  EXPECT_LE(metrics["cam_from_lidar_rotation_error_deg"].get<double>(), 0.05);
  // 8 stations, not the default 25: the translation bound is a regression bound (measured 2.1-3.1 mm;
  // the 25-station demo gives 0.9 mm). The reported covariance is NOT checked here: on these 8
  // stations its vertical (camera y) sigma, 0.75 mm, is about 2x too small (error 2.9 mm): a known
  // defect of the uncertainty estimate with only two tilted stations.
  EXPECT_LE(metrics["cam_from_lidar_translation_error_mm"].get<double>(), 5.0);
  EXPECT_LE(metrics["pose_position_error_mean_mm"].get<double>(), 2.0);

  // The existing COLMAP workflow on the same database: `colmap mapper`'s model (arbitrary scale and
  // frame) rescaled to metres by the depth priors, cam_from_lidar by hand-eye, then the joint adjuster.
  fs::create_directories(dir.File("ws/mapper"));
  for (const std::string& step :
       {kColmap + " mapper --database_path " + dir.File("ws/database.db") +
            " --image_path " + dataset + "/images --output_path " +
            dir.File("ws/mapper") + " --Mapper.ba_refine_focal_length 0" +
            " --Mapper.ba_refine_extra_params 0 --Mapper.num_threads 2",
        kCli + " pose_initializer --database_path " +
            dir.File("ws/database.db") + " --dataset_path " + dataset +
            " --registration_path " + dir.File("ws/lidar") + " --input_path " +
            dir.File("ws/mapper/0") + " --output_path " +
            dir.File("ws/mapper_initial"),
        kCli + " joint_adjuster --database_path " + dir.File("ws/database.db") +
            " --input_path " + dir.File("ws/mapper_initial") +
            " --dataset_path " + dataset + " --output_path " +
            dir.File("ws/mapper_joint"),
        kCli + " evaluate_calibration --dataset_path " + dataset +
            " --input_path " + dir.File("ws/mapper_joint") + " --output_path " +
            dir.File("ws/mapper_evaluation")}) {
    const auto result = RunCommand(step);
    ASSERT_EQ(result.exit_code, 0) << step << "\n" << result.output;
  }
  const nlohmann::json mapper_init =
      ReadJson(dir.File("ws/mapper_initial/initialization.json"));
  EXPECT_EQ(mapper_init["extrinsic_source"], "hand-eye");
  EXPECT_NE(mapper_init["scale_to_metres"].get<double>(), 1.0);
  const nlohmann::json from_mapper =
      ReadJson(dir.File("ws/mapper_evaluation/metrics.json"));
  std::cout << "from colmap mapper's model (scale "
            << mapper_init["scale_to_metres"] << "): cam_from_lidar error "
            << from_mapper["cam_from_lidar_rotation_error_deg"] << " deg, "
            << from_mapper["cam_from_lidar_translation_error_mm"]
            << " mm; poses mean " << from_mapper["pose_position_error_mean_mm"]
            << " mm (" << from_mapper["num_stations_evaluated"] << " stations)"
            << std::endl;
  // COLMAP's incremental mapper registers only part of 8 stations 45 deg apart (3 here); the
  // rescaled model must still be metric and calibrate cam_from_lidar.
  EXPECT_GE(from_mapper["num_stations_evaluated"].get<int>(), 3);
  EXPECT_LE(from_mapper["cam_from_lidar_rotation_error_deg"].get<double>(),
            0.05);
  EXPECT_LE(from_mapper["cam_from_lidar_translation_error_mm"].get<double>(),
            5.0);
  EXPECT_LE(from_mapper["pose_position_error_mean_mm"].get<double>(), 2.0);

  // A second run finds every step done.
  const auto again = RunCommand(command);
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(again.output.find(" ran "), std::string::npos) << again.output;
  EXPECT_NE(again.output.find("joint_adjuster          skipped"),
            std::string::npos)
      << again.output;
}

// Few stations around a square pillar: the image graph falls apart, LiDAR edges hold it together.
// Hand-eye needs image and LiDAR edges on the same pairs; here it cannot work, and without rig.json's
// guess the pipeline must stop saying so. With the guess every station is registered.
TEST(PipelineTest, LidarBridgesADisconnectedImageGraph) {
  testing::ScopedTempDir dir;
  const std::string dataset =
      Simulate(dir, "square_pillar", 5, 0.6, 200000, true);
  const StationDataset with_guess = ReadStationDataset(dataset);
  StationRig rig = with_guess.rig;
  rig.cam_from_lidar_guess.reset();
  WriteRigJson(dataset + "/rig.json", rig);
  const auto refused = RunCommand(kCli + " pipeline --dataset_path " + dataset +
                                  " --workspace_path " + dir.File("ws"));
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("degenerate motion for hand-eye calibration"),
            std::string::npos)
      << refused.output;
  EXPECT_NE(refused.output.find("add cam_from_lidar_guess"), std::string::npos);
  WriteRigJson(dataset + "/rig.json",
               with_guess.rig);  // the finished steps are kept
  const auto run = RunCommand(kCli + " pipeline --dataset_path " + dataset +
                              " --workspace_path " + dir.File("ws"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const int components = ImageGraphComponents(dir.File("ws/database.db"), 20);
  std::cout << "image graph: " << components << " components" << std::endl;
  EXPECT_GT(components, 1) << "the case needs a disconnected image graph";
  colmap::Reconstruction reconstruction;
  reconstruction.Read(dir.File("ws/sparse/joint"));
  EXPECT_EQ(reconstruction.NumRegImages(), 5u);
  // No image landmark joins the stations here: the report must say that cam_from_lidar is not
  // calibrated rather than pretend.
  const nlohmann::json report =
      ReadJson(dir.File("ws/sparse/joint/report.json"));
  const std::string verdict = report["observability_verdict"];
  std::cout << "square pillar verdict: " << verdict << std::endl;
  EXPECT_NE(
      verdict.find("cam_from_lidar cannot be calibrated: no image landmark"),
      std::string::npos)
      << verdict;
}

}  // namespace
}  // namespace colmap_lidar
