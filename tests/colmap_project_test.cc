// Adding a LiDAR to an existing COLMAP project: a database made by the user's own `colmap
// feature_extractor` and `colmap exhaustive_matcher` on flat file names (000.png, ...), taken over by
// the pipeline with --Import.image_name_format "{station}.png": the user's images, keypoints and
// matches are reused (no second copy, no second extraction), the camera takes rig.json's calibration,
// and the pipeline calibrates cam_from_lidar on it.
#include "colmap_ext/station_dataset.h"
#include "tests/testing/pipeline_fixture.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/database.h"

#include <gtest/gtest.h>

#include <map>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::kCli;
using testing::kColmap;
using testing::ReadJson;
using testing::RunCommand;

// Image name -> number of keypoints.
std::map<std::string, size_t> Keypoints(const std::string& database_path) {
  const colmap::Database database(database_path);
  std::map<std::string, size_t> keypoints;
  for (const colmap::Image& image : database.ReadAllImages()) {
    keypoints[image.Name()] = database.ReadKeypoints(image.ImageId()).size();
  }
  return keypoints;
}

void RunOrFail(const std::string& command) {
  const auto result = RunCommand(command);
  ASSERT_EQ(result.exit_code, 0) << command << "\n" << result.output;
}

TEST(ColmapProjectTest, AUserDatabaseWithItsOwnImageNamesIsReused) {
  testing::ScopedTempDir dir;
  const std::string dataset =
      testing::Simulate(dir.File("dataset"), "t_specimen", 6, 0.5, 200000, true);
  const StationDataset stations = ReadStationDataset(dataset);
  fs::create_directories(dir.File("photos"));
  for (const std::string& station : stations.stations) {
    fs::copy_file(dataset + "/images/left/" + station + ".png",
                  dir.File("photos/" + station + ".png"));
  }
  fs::create_directories(dir.File("ws"));
  const std::string database = dir.File("ws/database.db");
  RunOrFail(
      kColmap + " feature_extractor --database_path " + database + " --image_path " +
      dir.File("photos") +
      " --ImageReader.single_camera 1 --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads 2");
  RunOrFail(kColmap + " exhaustive_matcher --database_path " + database +
            " --SiftMatching.use_gpu 0 --SiftMatching.num_threads 2");
  const std::map<std::string, size_t> before = Keypoints(database);
  ASSERT_EQ(before.size(), stations.stations.size());

  // A pattern under which the stations have no image is refused, naming it; the database is kept.
  const std::string pipeline = kCli + " pipeline --dataset_path " + dataset + " --workspace_path " +
                               dir.File("ws") + " --Import.image_path " + dir.File("photos");
  const auto refused = RunCommand(pipeline + " --Import.image_name_format {station}.jpg");
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("station 000 has no image 000.jpg"), std::string::npos)
      << refused.output;
  EXPECT_EQ(Keypoints(database), before);

  const auto run = RunCommand(pipeline + " --Import.image_name_format {station}.png");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // The same images with the same keypoints: nothing added, nothing extracted again.
  EXPECT_EQ(Keypoints(database), before);
  {
    const colmap::Database db(database);
    ASSERT_EQ(db.NumCameras(), 1u);
    const colmap::Camera camera = db.ReadAllCameras().front();
    EXPECT_EQ(camera.ModelName(), stations.rig.left.ModelName());
    EXPECT_EQ(camera.params, stations.rig.left.params);
  }
  const nlohmann::json metrics = ReadJson(dir.File("ws/evaluation/metrics.json"));
  std::cout << "user database: cam_from_lidar " << metrics["cam_from_lidar_rotation_error_deg"]
            << " deg, " << metrics["cam_from_lidar_translation_error_mm"] << " mm, "
            << metrics["num_stations_evaluated"] << " stations" << std::endl;
  EXPECT_EQ(metrics["num_stations_evaluated"].get<int>(), 6);
  // Measured 0.117 deg / 6.2 mm (6 half-size stations, COLMAP's default SIFT and matching): 3x.
  EXPECT_LE(metrics["cam_from_lidar_rotation_error_deg"].get<double>(), 0.35);
  EXPECT_LE(metrics["cam_from_lidar_translation_error_mm"].get<double>(), 19.0);
}

}  // namespace
}  // namespace colmap_lidar
