// The real `colmap` executable as a client: databases that carry our tables stay usable by COLMAP, and
// COLMAP's own SIFT pipeline finds and verifies matches between neighbouring simulated stations.
#include "bridge/simulation/simulate_dataset.h"
#include "colmap_ext/extension_database.h"
#include "colmap_ext/station_dataset.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/database.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;

const std::string kColmap = COLMAP_LIDAR_COLMAP_EXE;

std::string SiftCommands(const std::string& database, const std::string& images) {
  return kColmap + " feature_extractor --database_path " + database + " --image_path " + images +
         " --ImageReader.camera_model PINHOLE --ImageReader.single_camera 1"
         " --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads 2"
         " --SiftExtraction.max_num_features 2048 && " +
         kColmap + " exhaustive_matcher --database_path " + database +
         " --SiftMatching.use_gpu 0 --SiftMatching.num_threads 2";
}

// Simulates `num_stations` of the default scene (images only matter here; few LiDAR points).
std::string SimulateImages(const testing::ScopedTempDir& dir, int num_stations) {
  sim::SimulationOptions options;
  options.output_path = dir.File("dataset");
  options.num_stations = num_stations;
  options.lidar_points = 5000;
  sim::SimulateDataset(options);
  return options.output_path;
}

TEST(ColmapClientTest, ColmapKeepsUsingADatabaseWithOurTables) {
  testing::ScopedTempDir dir;
  const std::string dataset_path = SimulateImages(dir, 3);
  const std::string database = dir.File("database.db");
  ASSERT_EQ(RunCommand(kColmap + " database_creator --database_path " + database).exit_code, 0);
  { ExtensionDatabase extension(database); }  // adds our tables to COLMAP's fresh database

  // COLMAP extracts and matches into it, unaware of our tables.
  const auto sift = RunCommand(SiftCommands(database, dataset_path + "/images/left"));
  ASSERT_EQ(sift.exit_code, 0) << sift.output;

  std::vector<colmap::image_t> image_ids;
  {
    colmap::Database colmap_database(database);
    for (const colmap::Image& image : colmap_database.ReadAllImages()) {
      image_ids.push_back(image.ImageId());
    }
    EXPECT_GT(colmap_database.NumVerifiedImagePairs(), 0u);
  }
  ASSERT_EQ(image_ids.size(), 3u);
  {
    ExtensionDatabase extension(database);
    extension.WriteDepthPriors(image_ids[0], {{0, 2.5, 0.01}, {3, 2.6, 0.01}});
    LidarFrame frame;
    frame.image_id = image_ids[1];
    frame.path = "lidar/001.pcd";
    extension.WriteLidarFrame(frame);
  }
  // COLMAP re-matches and cleans matches with our rows present; our rows survive.
  for (const std::string& command :
       {kColmap + " exhaustive_matcher --database_path " + database + " --SiftMatching.use_gpu 0",
        kColmap + " database_cleaner --type matches --database_path " + database}) {
    const auto result = RunCommand(command);
    ASSERT_EQ(result.exit_code, 0) << command << "\n" << result.output;
  }
  {
    ExtensionDatabase extension(database);
    EXPECT_EQ(extension.NumDepthPriors(), 2u);
    EXPECT_EQ(extension.ReadLidarFrames().size(), 1u);
  }
  // Deleting COLMAP's images cascades into our tables: no dangling rows.
  const auto clean =
      RunCommand(kColmap + " database_cleaner --type images --database_path " + database);
  ASSERT_EQ(clean.exit_code, 0) << clean.output;
  ExtensionDatabase extension(database);
  EXPECT_EQ(extension.NumDepthPriors(), 0u);
  EXPECT_TRUE(extension.ReadLidarFrames().empty());
}

TEST(ColmapClientTest, ColmapSiftMatchesNeighbouringStationsOfTheDefaultDataset) {
  testing::ScopedTempDir dir;
  const std::string dataset_path = SimulateImages(dir, 25);
  const StationDataset dataset = ReadStationDataset(dataset_path);
  const std::string database = dir.File("database.db");
  const auto sift = RunCommand(SiftCommands(database, dataset_path + "/images/left"));
  ASSERT_EQ(sift.exit_code, 0) << sift.output;

  colmap::Database colmap_database(database);
  std::map<std::string, colmap::image_t> ids;
  for (const colmap::Image& image : colmap_database.ReadAllImages()) {
    ids[image.Name()] = image.ImageId();
  }
  ASSERT_EQ(ids.size(), 25u);
  // The default motion: 20 tripod stations around the structure (000-019), then 5 tilted ones.
  int num_matched_neighbours = 0;
  for (int i = 0; i < 20; ++i) {
    const colmap::image_t a = ids.at(dataset.stations[i] + ".png");
    const colmap::image_t b = ids.at(dataset.stations[(i + 1) % 20] + ".png");
    const colmap::TwoViewGeometry geometry = colmap_database.ReadTwoViewGeometry(a, b);
    if (geometry.inlier_matches.size() >= 30) ++num_matched_neighbours;
  }
  std::cout << "neighbouring tripod stations with >= 30 verified SIFT matches: "
            << num_matched_neighbours << " of 20" << std::endl;
  EXPECT_GE(num_matched_neighbours, 18);
}

// Closed choices are given by name and parsed once, after the command line: an unknown name is one
// error naming the option and its choices, before any file is read; "auto" is the pipeline's alone.
TEST(CliTest, ClosedChoicesAreRefusedByNameBeforeAnyFileIsRead) {
  const std::string cli = COLMAP_LIDAR_CLI_EXE;
  testing::ScopedTempDir dir;
  const std::string pipeline =
      cli + " pipeline --dataset_path " + dir.File("d") + " --workspace_path " + dir.File("ws");
  const auto bad_mode = RunCommand(pipeline + " --mode bogus");
  EXPECT_NE(bad_mode.exit_code, 0);
  EXPECT_NE(
      bad_mode.output.find("unknown --mode 'bogus' (expected joint, precalibrated or stereo_only)"),
      std::string::npos)
      << bad_mode.output;
  // Accepted choices get as far as the missing dataset.
  const auto auto_matcher =
      RunCommand(pipeline + " --Import.matcher auto --LidarRegistrator.method odometry");
  EXPECT_NE(auto_matcher.exit_code, 0);
  EXPECT_NE(auto_matcher.output.find("dataset directory does not exist"), std::string::npos)
      << auto_matcher.output;
  const auto import_auto = RunCommand(cli + " import_dataset --dataset_path " + dir.File("d") +
                                      " --database_path " + dir.File("x.db") + " --matcher auto");
  EXPECT_NE(import_auto.exit_code, 0);
  EXPECT_NE(import_auto.output.find("unknown --matcher 'auto'"), std::string::npos)
      << import_auto.output;
  const auto bad_removal =
      RunCommand(cli + " lidar_registrator --lidar_path " + dir.File("l") + " --output_path " +
                 dir.File("o") + " --remove_moving_points maybe");
  EXPECT_NE(bad_removal.output.find("unknown --remove_moving_points 'maybe'"), std::string::npos)
      << bad_removal.output;
  const auto bad_axis =
      RunCommand(cli + " joint_adjuster --database_path " + dir.File("x.db") + " --input_path " +
                 dir.File("m") + " --dataset_path " + dir.File("d") + " --output_path " +
                 dir.File("o") + " --hold_translation x,q");
  EXPECT_NE(bad_axis.exit_code, 0);
  EXPECT_NE(bad_axis.output.find("--hold_translation: unknown axis 'q'"), std::string::npos)
      << bad_axis.output;
  EXPECT_FALSE(fs::exists(dir.File("ws")));
  EXPECT_FALSE(fs::exists(dir.File("o")));
  EXPECT_FALSE(fs::exists(dir.File("x.db")));
}

TEST(CliTest, HelpVersionAndErrors) {
  const std::string cli = COLMAP_LIDAR_CLI_EXE;
  const auto help = RunCommand(cli + " help");
  EXPECT_EQ(help.exit_code, 0);
  for (const char* command : {"database_creator", "database_info", "simulate_dataset"}) {
    EXPECT_NE(help.output.find(command), std::string::npos) << command;
  }
  const auto version = RunCommand(cli + " version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find("COLMAP 3.10"), std::string::npos) << version.output;

  const auto unknown = RunCommand(cli + " no_such_command");
  EXPECT_NE(unknown.exit_code, 0);
  EXPECT_NE(unknown.output.find("unknown command 'no_such_command'"), std::string::npos);

  const auto bad_option = RunCommand(cli + " database_creator --no_such_option 1");
  EXPECT_NE(bad_option.exit_code, 0);
  EXPECT_NE(bad_option.output.find("no_such_option"), std::string::npos) << bad_option.output;

  testing::ScopedTempDir dir;
  const auto bad_scene =
      RunCommand(cli + " simulate_dataset --scene moon --output_path " + dir.File("d"));
  EXPECT_NE(bad_scene.exit_code, 0);
  EXPECT_NE(bad_scene.output.find("Unknown scene 'moon'"), std::string::npos) << bad_scene.output;
  EXPECT_FALSE(fs::exists(dir.File("d")));

  const auto missing_db = RunCommand(cli + " database_info --database_path " + dir.File("x.db"));
  EXPECT_NE(missing_db.exit_code, 0);
  EXPECT_NE(missing_db.output.find(dir.File("x.db")), std::string::npos) << missing_db.output;
  EXPECT_FALSE(fs::exists(dir.File("x.db"))) << "database_info must not create a database";

  // A nested option check (the hold threshold inside the joint adjuster's options) is acted on: the
  // value is refused before any file is read.
  const auto bad_threshold =
      RunCommand(cli + " joint_adjuster --database_path " + dir.File("x.db") + " --input_path " +
                 dir.File("m") + " --dataset_path " + dir.File("d") + " --output_path " +
                 dir.File("o") + " --hold_translation_mm -1");
  EXPECT_NE(bad_threshold.exit_code, 0);
  EXPECT_NE(bad_threshold.output.find("hold_translation_mm > 0"), std::string::npos)
      << bad_threshold.output;
  EXPECT_FALSE(fs::exists(dir.File("o")));

  // An option joint_adjuster no longer takes is refused with what decides its value now.
  const auto removed =
      RunCommand(cli + " joint_adjuster --database_path " + dir.File("x.db") + " --input_path " +
                 dir.File("m") + " --dataset_path " + dir.File("d") + " --output_path " +
                 dir.File("o") + " --depth_weight 2");
  EXPECT_NE(removed.exit_code, 0);
  EXPECT_NE(removed.output.find("--depth_weight is no longer an option: each data group's weight "
                                "is estimated"),
            std::string::npos)
      << removed.output;
  EXPECT_FALSE(fs::exists(dir.File("o")));
  const auto removed_noise =
      RunCommand(cli + " joint_adjuster --database_path " + dir.File("x.db") + " --input_path " +
                 dir.File("m") + " --dataset_path " + dir.File("d") + " --output_path " +
                 dir.File("o") + " --sigma_lidar_m 0.01");
  EXPECT_NE(removed_noise.output.find("rig.json's lidar.range_noise_m"), std::string::npos)
      << removed_noise.output;
  const auto removed_in_pipeline =
      RunCommand(cli + " pipeline --dataset_path " + dir.File("d") + " --workspace_path " +
                 dir.File("ws") + " --JointAdjuster.loss=cauchy");
  EXPECT_NE(removed_in_pipeline.exit_code, 0);
  EXPECT_NE(removed_in_pipeline.output.find("--JointAdjuster.loss is no longer an option"),
            std::string::npos)
      << removed_in_pipeline.output;
  EXPECT_FALSE(fs::exists(dir.File("ws")));
  // The same in a project file (--project_path), in a section or at the top level.
  std::ofstream(dir.File("project.ini")) << "[JointAdjuster]\nhold_translation_mm=30\n"
                                            "max_landmark_plane_sigmas = 2\n";
  const auto removed_in_project =
      RunCommand(cli + " pipeline --project_path " + dir.File("project.ini"));
  EXPECT_NE(removed_in_project.exit_code, 0);
  EXPECT_NE(removed_in_project.output.find(dir.File("project.ini") +
                                           ": JointAdjuster.max_landmark_plane_sigmas is no "
                                           "longer an option"),
            std::string::npos)
      << removed_in_project.output;

  // The pipeline registers every step's options under the step's section; a bad one is refused
  // before the workspace is created.
  const auto pipeline_help = RunCommand(cli + " pipeline --help");
  for (const char* option : {"--JointAdjuster.hold_translation_mm",
                             "--StereoDepth.block_size",
                             "--LidarRegistrator.max_neighbors arg (=4)",
                             "--Densifier.fill_holes",
                             "--SiftExtraction.max_image_size"}) {
    EXPECT_NE(pipeline_help.output.find(option), std::string::npos) << option;
  }
  const auto bad_step_option =
      RunCommand(cli + " pipeline --dataset_path " + dir.File("d") + " --workspace_path " +
                 dir.File("ws") + " --JointAdjuster.hold_translation_mm -1");
  EXPECT_NE(bad_step_option.exit_code, 0);
  EXPECT_NE(bad_step_option.output.find("hold_translation_mm > 0"), std::string::npos)
      << bad_step_option.output;
  EXPECT_FALSE(fs::exists(dir.File("ws")));
}

TEST(CliTest, OptionsFromAProjectIniFile) {
  const std::string cli = COLMAP_LIDAR_CLI_EXE;
  testing::ScopedTempDir dir;
  std::ofstream(dir.File("project.ini"))
      << "output_path=" << dir.File("d") << "\nscene=cylinder_pillar\nnum_stations=2\n"
      << "lidar_points=2000\nimage_scale=0.2\n";
  const auto result =
      RunCommand(cli + " simulate_dataset --project_path " + dir.File("project.ini"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(ReadStationDataset(dir.File("d")).stations.size(), 2u);
  const auto db = RunCommand(cli + " database_creator --database_path " + dir.File("db.db") +
                             " && " + cli + " database_info --database_path " + dir.File("db.db"));
  ASSERT_EQ(db.exit_code, 0) << db.output;
  EXPECT_NE(db.output.find("depth priors:  0"), std::string::npos) << db.output;
}

}  // namespace
}  // namespace colmap_lidar
