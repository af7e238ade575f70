// The pipeline end to end through the CLI, without a cam_from_lidar guess: import, stereo depth, depth
// priors, LiDAR registration, initialisation (hand-eye), joint adjustment, dense model, evaluation;
// restartable.
#include "colmap_ext/station_dataset.h"
#include "tests/simulator/simulate_dataset.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/mvs/depth_map.h"
#include "colmap/scene/database.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/sensor/models.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numeric>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;
using testing::RunStep;

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

// evaluate_model on a dense cloud of the model whose alignment evaluate_calibration wrote.
nlohmann::json EvaluateCloud(const std::string& cloud,
                             const std::string& dataset,
                             const std::string& truth_from_model,
                             const std::string& output) {
  RunStep(kCli + " evaluate_model --model_path " + cloud + " --ground_truth_path " + dataset +
          "/ground_truth/surface.ply --truth_from_model " + truth_from_model + " --output_path " +
          output);
  return ReadJson(output + "/metrics.json");
}

void PrintCloudMetrics(const std::string& name, const nlohmann::json& m) {
  std::cout << std::fixed << std::setprecision(2) << "  " << std::left << std::setw(34) << name
            << " mean " << 1000 * m["mean_m"].get<double>() << " mm, median "
            << 1000 * m["median_m"].get<double>() << " mm, completeness 2/5/10 mm "
            << m["completeness_2mm"].get<double>() << "/" << m["completeness_5mm"].get<double>()
            << "/" << m["completeness_10mm"].get<double>() << ", density "
            << m["density_points_per_cm2"].get<double>() << " points/cm^2" << std::endl;
}

// The dense model of a pipeline workspace (issue 8): LiDAR-refined fused.ply against the unrefined
// stereo on the same poses and against the stereo-only pipeline; COLMAP's own fusion and Poisson
// mesher on our dense workspace; the LiDAR map; a missing depth map.
void CheckDenseModel(const testing::ScopedTempDir& dir, const std::string& dataset) {
  const std::string ws = dir.File("ws");
  const std::string truth_from_joint = ws + "/evaluation/truth_from_model.txt";
  const nlohmann::json refined = ReadJson(ws + "/evaluation/model/metrics.json");
  for (const std::string& step :
       {kCli + " densifier --input_path " + ws + "/sparse/joint --dataset_path " + dataset +
            " --depth_path " + ws + "/stereo --output_path " + ws +
            "/dense_unrefined --refine_with_lidar 0",
        kCli + " joint_adjuster --database_path " + ws + "/database.db --input_path " + ws +
            "/sparse/initial --dataset_path " + dataset + " --output_path " + ws +
            "/sparse/stereo_only --mode stereo_only",
        kCli + " evaluate_calibration --dataset_path " + dataset + " --input_path " + ws +
            "/sparse/stereo_only --output_path " + ws + "/evaluation_stereo_only",
        kCli + " densifier --input_path " + ws + "/sparse/stereo_only --dataset_path " + dataset +
            " --depth_path " + ws + "/stereo --output_path " + ws +
            "/dense_stereo_only --refine_with_lidar 0"}) {
    const auto result = RunCommand(step);
    ASSERT_EQ(result.exit_code, 0) << step << "\n" << result.output;
  }
  const nlohmann::json unrefined = EvaluateCloud(ws + "/dense_unrefined/fused.ply",
                                                 dataset,
                                                 truth_from_joint,
                                                 ws + "/evaluation/model_unrefined");
  const nlohmann::json stereo_only =
      EvaluateCloud(ws + "/dense_stereo_only/fused.ply",
                    dataset,
                    ws + "/evaluation_stereo_only/truth_from_model.txt",
                    ws + "/evaluation/model_stereo_only");
  const nlohmann::json lidar_map = EvaluateCloud(
      ws + "/dense/lidar_map.ply", dataset, truth_from_joint, ws + "/evaluation/lidar_map");
  std::cout << "dense models against the true surface:" << std::endl;
  PrintCloudMetrics("LiDAR-refined (fused.ply)", refined);
  PrintCloudMetrics("stereo, joint poses, unrefined", unrefined);
  PrintCloudMetrics("stereo-only pipeline", stereo_only);
  PrintCloudMetrics("LiDAR map", lidar_map);
  // Measured: mean 2.06 vs 2.52 vs 2.59 mm; completeness at 2 mm 0.61 vs 0.56 vs 0.54 (removed stereo
  // is replaced from the LiDAR surface, closer to the truth); at 5 and 10 mm equal within 0.005:
  // stereo more than 1 cm off that fold 2 cannot replace (foreground fattened across a depth edge)
  // is removed, and it lay within 10 mm of the foreground's border.
  EXPECT_LT(refined["mean_m"].get<double>(), 0.9 * unrefined["mean_m"].get<double>());
  EXPECT_LT(refined["mean_m"].get<double>(), 0.9 * stereo_only["mean_m"].get<double>());
  EXPECT_LT(refined["mean_m"].get<double>(), 0.0025);
  for (const auto* other : {&unrefined, &stereo_only}) {
    EXPECT_GT(refined["completeness_2mm"].get<double>(),
              (*other)["completeness_2mm"].get<double>() + 0.02);
    EXPECT_GT(refined["completeness_5mm"].get<double>(),
              (*other)["completeness_5mm"].get<double>() - 0.01);
    EXPECT_GT(refined["completeness_10mm"].get<double>(),
              (*other)["completeness_10mm"].get<double>() - 0.01);
  }
  EXPECT_GT(refined["density_points_per_cm2"].get<double>(), 20);
  // The LiDAR map is in the model's frame (1 cm range noise: mean distance about 8 mm).
  EXPECT_LT(lidar_map["mean_m"].get<double>(), 0.012);
  EXPECT_LT(lidar_map["icp_translation_m"].get<double>(), 0.005);
  const nlohmann::json report = ReadJson(ws + "/dense/densifier.json");
  size_t filled = 0, removed = 0;
  for (const auto& station : report["stations"]) {
    filled += station["filled"].get<size_t>();
    removed += station["stereo_removed"].get<size_t>();
  }
  EXPECT_GT(filled, 10000u);
  EXPECT_GT(removed, 10000u);
  EXPECT_TRUE(fs::is_regular_file(ws + "/dense/stereo/depth_maps/left/000.png.geometric.bin"));
  EXPECT_TRUE(fs::is_regular_file(ws + "/dense/stereo/previews/000.png"));

  // COLMAP's own tools on our dense workspace. Stations are few and far apart, so a fused point
  // needs 2 agreeing pixels here, not COLMAP's default 5.
  const std::string colmap_fused = ws + "/dense/colmap_fused.ply";
  for (const std::string& step :
       {kColmap + " stereo_fusion --workspace_path " + ws +
            "/dense --input_type geometric --output_path " + colmap_fused +
            " --StereoFusion.min_num_pixels 2 --StereoFusion.num_threads 2",
        kColmap + " poisson_mesher --input_path " + colmap_fused + " --output_path " + ws +
            "/dense/meshed-poisson.ply"}) {
    const auto result = RunCommand(step);
    ASSERT_EQ(result.exit_code, 0) << step << "\n" << result.output;
  }
  const nlohmann::json fused_by_colmap =
      EvaluateCloud(colmap_fused, dataset, truth_from_joint, ws + "/evaluation/colmap_fusion");
  PrintCloudMetrics("colmap stereo_fusion of our maps", fused_by_colmap);
  EXPECT_GT(fused_by_colmap["num_evaluated"].get<size_t>(), 50000u);
  // Where we measured (the workspace's -0.5 px principal point), multi-view consistent: 1.1-1.3 mm.
  EXPECT_LT(fused_by_colmap["mean_m"].get<double>(), 0.002);
  EXPECT_GT(fs::file_size(ws + "/dense/meshed-poisson.ply"), 10000u);

  // Stereo holes (a textureless or specular patch): the middle ninth of every stereo map is emptied;
  // fold 2 must fill it from the LiDAR.
  {
    fs::create_directories(ws + "/stereo_holes/depth_maps");
    fs::copy_file(ws + "/stereo/stereo.json", ws + "/stereo_holes/stereo.json");
    for (const auto& entry : fs::directory_iterator(ws + "/stereo/depth_maps")) {
      colmap::mvs::DepthMap map;
      map.Read(entry.path().string());
      const size_t w = map.GetWidth(), h = map.GetHeight();
      for (size_t row = h / 3; row < 2 * h / 3; ++row) {
        for (size_t col = w / 3; col < 2 * w / 3; ++col) map.Set(row, col, 0.f);
      }
      map.Write(ws + "/stereo_holes/depth_maps/" + entry.path().filename().string());
    }
    nlohmann::json holes[2];
    for (int refine = 0; refine < 2; ++refine) {
      const std::string out = ws + "/dense_holes" + std::to_string(refine);
      const auto run =
          RunCommand(kCli + " densifier --input_path " + ws + "/sparse/joint --dataset_path " +
                     dataset + " --depth_path " + ws + "/stereo_holes --output_path " + out +
                     " --refine_with_lidar " + std::to_string(refine));
      ASSERT_EQ(run.exit_code, 0) << run.output;
      holes[refine] = EvaluateCloud(out + "/fused.ply",
                                    dataset,
                                    truth_from_joint,
                                    ws + "/evaluation/model_holes" + std::to_string(refine));
    }
    PrintCloudMetrics("stereo with holes, unrefined", holes[0]);
    PrintCloudMetrics("stereo with holes, LiDAR-refined", holes[1]);
    EXPECT_GT(holes[1]["completeness_5mm"].get<double>(),
              holes[0]["completeness_5mm"].get<double>() + 0.03);
    EXPECT_LT(holes[1]["mean_m"].get<double>(), holes[0]["mean_m"].get<double>());
  }

  // A camera model with distortion goes through COLMAP's undistortion (cameras, keypoints) and our
  // resampling of depth maps and images: OPENCV with zero coefficients must give the same model.
  {
    colmap::Reconstruction model;
    model.Read(ws + "/sparse/joint");
    for (const auto& [camera_id, camera] : model.Cameras()) {
      colmap::Camera& opencv = model.Camera(camera_id);
      opencv.model_id = colmap::CameraModelNameToId("OPENCV");
      opencv.params = {camera.FocalLengthX(),
                       camera.FocalLengthY(),
                       camera.PrincipalPointX(),
                       camera.PrincipalPointY(),
                       0,
                       0,
                       0,
                       0};
    }
    fs::create_directories(ws + "/sparse/joint_opencv");
    model.Write(ws + "/sparse/joint_opencv");
    const auto run = RunCommand(
        kCli + " densifier --input_path " + ws + "/sparse/joint_opencv" + " --cam_from_lidar " +
        ws + "/sparse/joint/cam_from_lidar.txt --dataset_path " + dataset + " --depth_path " + ws +
        "/stereo --output_path " + ws + "/dense_opencv");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("is undistorted to PINHOLE"), std::string::npos);
    const nlohmann::json opencv = EvaluateCloud(
        ws + "/dense_opencv/fused.ply", dataset, truth_from_joint, ws + "/evaluation/model_opencv");
    PrintCloudMetrics("same, camera given as OPENCV", opencv);
    // COLMAP's undistorted camera is 1027x750, not 1028x752: the maps are resampled to the nearest
    // pixel (measured 2.10 vs 2.06 mm; completeness at 2 mm 0.59 vs 0.61, at 5 mm equal).
    EXPECT_NEAR(opencv["mean_m"].get<double>(), refined["mean_m"].get<double>(), 2e-4);
    EXPECT_NEAR(
        opencv["completeness_5mm"].get<double>(), refined["completeness_5mm"].get<double>(), 0.01);
  }

  // A missing depth map: one error naming the file, nothing written.
  fs::create_directories(ws + "/empty_stereo");
  const auto missing = RunCommand(kCli + " densifier --input_path " + ws +
                                  "/sparse/joint --dataset_path " + dataset + " --depth_path " +
                                  ws + "/empty_stereo --output_path " + ws + "/dense_missing");
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("empty_stereo/depth_maps/000.png.geometric.bin"), std::string::npos)
      << missing.output;
  EXPECT_FALSE(fs::exists(ws + "/dense_missing"));
  EXPECT_FALSE(fs::exists(ws + "/dense_missing.partial"));
}

TEST(PipelineTest, DefaultSceneWithoutAGuessEndToEndAndRestartable) {
  testing::ScopedTempDir dir;
  const std::string dataset = Simulate(dir, "t_specimen", 8, 1.0, 300000, false);
  ASSERT_FALSE(ReadStationDataset(dataset).rig.cam_from_lidar_guess);
  // A step's option given to the pipeline reaches the step.
  const std::string command = kCli + " pipeline --dataset_path " + dataset + " --workspace_path " +
                              dir.File("ws") + " --JointAdjuster.write_text 1";
  const auto run = RunCommand(command);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(fs::is_regular_file(dir.File("ws/sparse/joint/images.txt")));
  EXPECT_FALSE(fs::exists(dir.File("ws/sparse/initial/images.txt")));
  std::cout << run.output.substr(run.output.find("== Pipeline summary")) << std::endl;
  const nlohmann::json init = ReadJson(dir.File("ws/sparse/initial/initialization.json"));
  EXPECT_EQ(init["extrinsic_source"], "hand-eye");
  EXPECT_TRUE(init["hand_eye"]["unique"].get<bool>());
  const nlohmann::json metrics = ReadJson(dir.File("ws/evaluation/metrics.json"));
  std::cout << "pipeline without a guess: cam_from_lidar error "
            << metrics["cam_from_lidar_rotation_error_deg"] << " deg, "
            << metrics["cam_from_lidar_translation_error_mm"] << " mm; poses mean "
            << metrics["pose_position_error_mean_mm"] << " mm" << std::endl;
  EXPECT_EQ(metrics["num_stations_evaluated"].get<int>(), 8);
  EXPECT_LE(metrics["cam_from_lidar_rotation_error_deg"].get<double>(), 0.05);
  // 8 stations, not the default 25: the translation bound is a regression bound (measured 2.1-3.1 mm;
  // the 25-station demo gives 0.9 mm). The reported covariance is NOT checked here: on these 8
  // stations its vertical (camera y) sigma, 0.75 mm, is about 2x too small (error 2.9 mm): a known
  // defect of the uncertainty estimate with only two tilted stations.
  EXPECT_LE(metrics["cam_from_lidar_translation_error_mm"].get<double>(), 5.0);
  EXPECT_LE(metrics["pose_position_error_mean_mm"].get<double>(), 2.0);

  CheckDenseModel(dir, dataset);

  // The existing COLMAP workflow on the same database: `colmap mapper`'s model (arbitrary scale and
  // frame) rescaled to metres by the depth priors, cam_from_lidar by hand-eye, then the joint adjuster.
  fs::create_directories(dir.File("ws/mapper"));
  for (const std::string& step :
       {kColmap + " mapper --database_path " + dir.File("ws/database.db") + " --image_path " +
            dataset + "/images --output_path " + dir.File("ws/mapper") +
            " --Mapper.ba_refine_focal_length 0" +
            " --Mapper.ba_refine_extra_params 0 --Mapper.num_threads 2",
        kCli + " pose_initializer --database_path " + dir.File("ws/database.db") +
            " --dataset_path " + dataset + " --registration_path " + dir.File("ws/lidar") +
            " --input_path " + dir.File("ws/mapper/0") + " --output_path " +
            dir.File("ws/mapper_initial"),
        kCli + " joint_adjuster --database_path " + dir.File("ws/database.db") + " --input_path " +
            dir.File("ws/mapper_initial") + " --dataset_path " + dataset + " --output_path " +
            dir.File("ws/mapper_joint"),
        kCli + " evaluate_calibration --dataset_path " + dataset + " --input_path " +
            dir.File("ws/mapper_joint") + " --output_path " + dir.File("ws/mapper_evaluation")}) {
    const auto result = RunCommand(step);
    ASSERT_EQ(result.exit_code, 0) << step << "\n" << result.output;
  }
  const nlohmann::json mapper_init = ReadJson(dir.File("ws/mapper_initial/initialization.json"));
  EXPECT_EQ(mapper_init["extrinsic_source"], "hand-eye");
  EXPECT_NE(mapper_init["scale_to_metres"].get<double>(), 1.0);
  const nlohmann::json from_mapper = ReadJson(dir.File("ws/mapper_evaluation/metrics.json"));
  std::cout << "from colmap mapper's model (scale " << mapper_init["scale_to_metres"]
            << "): cam_from_lidar error " << from_mapper["cam_from_lidar_rotation_error_deg"]
            << " deg, " << from_mapper["cam_from_lidar_translation_error_mm"] << " mm; poses mean "
            << from_mapper["pose_position_error_mean_mm"] << " mm ("
            << from_mapper["num_stations_evaluated"] << " stations)" << std::endl;
  // COLMAP's incremental mapper registers only part of 8 stations 45 deg apart (3 here); the
  // rescaled model must still be metric and calibrate cam_from_lidar.
  EXPECT_GE(from_mapper["num_stations_evaluated"].get<int>(), 3);
  EXPECT_LE(from_mapper["cam_from_lidar_rotation_error_deg"].get<double>(), 0.05);
  EXPECT_LE(from_mapper["cam_from_lidar_translation_error_mm"].get<double>(), 5.0);
  EXPECT_LE(from_mapper["pose_position_error_mean_mm"].get<double>(), 2.0);

  // A second run finds every step done.
  const auto again = RunCommand(command);
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(again.output.find(" ran "), std::string::npos) << again.output;
  EXPECT_NE(again.output.find("joint_adjuster          skipped"), std::string::npos)
      << again.output;
}

// Few stations around a square pillar: the image graph falls apart, LiDAR edges hold it together.
// Hand-eye needs image and LiDAR edges on the same pairs; here it cannot work, and without rig.json's
// guess the pipeline must stop saying so. With the guess every station is registered.
TEST(PipelineTest, LidarBridgesADisconnectedImageGraph) {
  testing::ScopedTempDir dir;
  const std::string dataset = Simulate(dir, "square_pillar", 5, 0.6, 200000, true);
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
