// The front end through the CLI on simulated stations: import_dataset (COLMAP SIFT into the database),
// stereo_depth, depth_prior_extractor; accuracy against the simulator's ground truth; COLMAP's own
// mapper on the imported database; bad input.
#include "bridge/initialization/lidar_registration_files.h"
#include "bridge/simulation/scene.h"
#include "bridge/simulation/simulate_dataset.h"
#include "colmap_ext/extension_database.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/util/statistics.h"
#include "tests/testing/file_bytes.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/mvs/depth_map.h"
#include "colmap/scene/database.h"
#include "colmap/scene/reconstruction.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::FileBytes;
using testing::RunCommand;

const std::string kCli = COLMAP_LIDAR_CLI_EXE;
const std::string kColmap = COLMAP_LIDAR_COLMAP_EXE;
const std::string kSift = " --SiftExtraction.num_threads 2 --SiftMatching.num_threads 2";

std::string Simulate(const testing::ScopedTempDir& dir,
                     const std::string& name,
                     int num_stations,
                     sim::Motion motion,
                     double image_scale) {
  sim::SimulationOptions options;
  options.output_path = dir.File(name);
  options.num_stations = num_stations;
  options.motion = motion;
  options.image_scale = image_scale;
  options.lidar_points = 5000;
  sim::SimulateDataset(options);
  return options.output_path;
}

// The default scene and rig at full resolution (6 stations of the default two-axes motion).
TEST(FrontEndTest, DepthPriorsOfTheDefaultSceneMatchTheTruth) {
  testing::ScopedTempDir dir;
  const std::string dataset_path = Simulate(dir, "dataset", 6, sim::Motion::kTwoAxes, 1.0);
  const StationDataset dataset = ReadStationDataset(dataset_path);

  auto result = RunCommand(kCli + " stereo_depth --dataset_path " + dataset_path +
                           " --output_path " + dir.File("stereo"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::cout << result.output;
  ASSERT_TRUE(fs::exists(dir.File("stereo/stereo.json")));

  // Depth maps against the simulator's true depth maps, pixel by pixel.
  std::vector<double> pixel_errors, signed_pixel_errors;
  size_t num_true = 0, num_valid = 0;
  // Least squares of the relative depth error on the true relative inverse-depth change per row:
  // the slope is how many rows above (> 0) or below the disparity was effectively taken from.
  double gradient_squared = 0, gradient_times_error = 0;
  for (const std::string& station : dataset.stations) {
    colmap::mvs::DepthMap truth, depth;
    truth.Read(dataset.GroundTruthPath("depth/" + station + ".bin"));
    depth.Read(dir.File("stereo/depth_maps/" + station + ".png.geometric.bin"));
    ASSERT_EQ(depth.GetWidth(), truth.GetWidth());
    ASSERT_EQ(depth.GetHeight(), truth.GetHeight());
    EXPECT_TRUE(fs::exists(dir.File("stereo/previews/" + station + ".png")));
    EXPECT_TRUE(fs::exists(dir.File("stereo/confidence_maps/" + station + ".png")));
    for (size_t row = 0; row < depth.GetHeight(); ++row) {
      for (size_t col = 0; col < depth.GetWidth(); ++col) {
        const double z_true = truth.Get(row, col);
        if (z_true <= 0 || z_true > 20) continue;
        ++num_true;
        const double z = depth.Get(row, col);
        if (z <= 0) continue;
        ++num_valid;
        pixel_errors.push_back(std::abs(z - z_true) / z_true);
        signed_pixel_errors.push_back((z - z_true) / z_true);
        if (row == 0 || row + 1 == depth.GetHeight()) continue;
        const double above = truth.Get(row - 1, col), below = truth.Get(row + 1, col);
        if (above <= 0 || below <= 0 || std::abs(z - z_true) > 0.02 * z_true) continue;
        const double gradient = 0.5 * (1 / below - 1 / above) * z_true;
        if (std::abs(gradient) > 0.05) continue;  // a depth edge
        gradient_squared += gradient * gradient;
        gradient_times_error += gradient * (z - z_true) / z_true;
      }
    }
  }
  const double pixel_fraction = static_cast<double>(num_valid) / num_true;
  std::cout << "stereo depth: " << 100 * pixel_fraction
            << " % of pixels with depth; relative error median "
            << 100 * Quantile(pixel_errors, 0.5) << " %, 90th percentile "
            << 100 * Quantile(pixel_errors, 0.9) << " %; signed median "
            << 100 * Quantile(signed_pixel_errors, 0.5) << " %" << std::endl;
  const double vertical_shift_rows = gradient_times_error / gradient_squared;
  std::cout << "stereo depth: effective vertical shift on slanted surfaces " << vertical_shift_rows
            << " rows" << std::endl;
  EXPECT_GT(pixel_fraction, 0.6);
  EXPECT_LT(Quantile(pixel_errors, 0.5), 0.005);
  // SGBM's top-down paths alone shift by 0.7 rows (the ground too far: a bias of cam_from_lidar's
  // vertical translation); matching both vertical directions leaves 0.25.
  EXPECT_LT(std::abs(vertical_shift_rows), 0.45);

  result = RunCommand(kCli + " import_dataset --dataset_path " + dataset_path +
                      " --database_path " + dir.File("db.db") + kSift);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  result = RunCommand(kCli + " depth_prior_extractor --database_path " + dir.File("db.db") +
                      " --depth_path " + dir.File("stereo"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::cout << result.output;

  // Each prior against the exact depth of the keypoint's ray on the true scene.
  const sim::Scene scene = sim::Scene::Create("t_specimen");
  const auto cam_from_world = ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt"));
  const colmap::Database database(dir.File("db.db"));
  const ExtensionDatabase extension(dir.File("db.db"), ExtensionDatabase::Mode::kReadOnly);
  std::vector<double> relative_errors, normalised_errors, signed_errors;
  size_t num_keypoints = 0, num_priors = 0;
  for (const colmap::Image& image : database.ReadAllImages()) {
    const std::string station = fs::path(image.Name()).stem().string();
    const colmap::Rigid3d& pose = cam_from_world.at(station);
    const colmap::Camera camera = database.ReadCamera(image.CameraId());
    const colmap::FeatureKeypoints keypoints = database.ReadKeypoints(image.ImageId());
    const std::vector<DepthPrior> priors = extension.ReadDepthPriors(image.ImageId());
    num_keypoints += keypoints.size();
    num_priors += priors.size();
    const colmap::Rigid3d world_from_cam = colmap::Inverse(pose);
    for (const DepthPrior& prior : priors) {
      const colmap::FeatureKeypoint& keypoint = keypoints.at(prior.point2D_idx);
      const Eigen::Vector3d ray_in_cam =
          camera.CamFromImg(Eigen::Vector2d(keypoint.x, keypoint.y)).homogeneous();
      sim::RayHit hit;
      if (!scene.Intersect(world_from_cam.translation,
                           (world_from_cam.rotation * ray_in_cam).normalized(),
                           1000,
                           &hit)) {
        // A prior for a keypoint whose ray sees the sky: a gross error.
        relative_errors.push_back(1.0);
        normalised_errors.push_back(1e6);
        continue;
      }
      const double z_true = hit.t / ray_in_cam.norm();  // ray_in_cam has z = 1
      relative_errors.push_back(std::abs(prior.depth - z_true) / z_true);
      signed_errors.push_back((prior.depth - z_true) / z_true);
      normalised_errors.push_back(std::abs(prior.depth - z_true) / prior.sigma);
    }
  }
  const double fraction = static_cast<double>(num_priors) / num_keypoints;
  std::cout << std::setprecision(3) << "depth priors: " << num_priors << " of " << num_keypoints
            << " keypoints (" << 100 * fraction << " %); |error|/depth median "
            << 100 * Quantile(relative_errors, 0.5) << " %; |error|/sigma_d median "
            << Quantile(normalised_errors, 0.5) << ", 95th percentile "
            << Quantile(normalised_errors, 0.95)
            << " (ratio of observed error to sigma_d); signed median "
            << 100 * Quantile(signed_errors, 0.5) << " %" << std::endl;
  EXPECT_GE(fraction, 0.6);
  EXPECT_LE(Quantile(relative_errors, 0.5), 0.005);
  // sigma_d with sigma_p = 1 px must not be optimistic: 95 % of errors within 2 sigma.
  EXPECT_LE(Quantile(normalised_errors, 0.95), 2.0);
}

// COLMAP's own mapper reconstructs from the imported database; a second import adds nothing.
TEST(FrontEndTest, ImportedDatabaseIsIdempotentAndUsableByColmapMapper) {
  testing::ScopedTempDir dir;
  const std::string dataset_path = Simulate(dir, "dataset", 4, sim::Motion::kFixedRotation, 0.6);
  const std::string db = dir.File("db.db");
  const std::string import =
      kCli + " import_dataset --dataset_path " + dataset_path + " --database_path " + db + kSift;
  // An empty file, as an import killed while copying into a new database leaves it (SQLite rolls
  // the copy back): imported into as if new (before: "Not a COLMAP database" on every rerun).
  std::ofstream(db).close();
  auto result = RunCommand(import);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_FALSE(fs::exists(db + ".import-partial"));

  auto counts = [&db]() {
    const colmap::Database database(db);
    const ExtensionDatabase extension(db, ExtensionDatabase::Mode::kReadOnly);
    return std::vector<size_t>{database.NumCameras(),
                               database.NumImages(),
                               database.NumKeypoints(),
                               database.NumMatches(),
                               database.NumVerifiedImagePairs(),
                               extension.ReadLidarFrames().size()};
  };
  const std::vector<size_t> first = counts();
  EXPECT_EQ(first[0], 1u);
  EXPECT_EQ(first[1], 4u);
  EXPECT_EQ(first[5], 4u);
  EXPECT_GE(first[4], 3u);
  {
    const colmap::Database database(db);
    const colmap::Camera camera = database.ReadCamera(1);
    const StationDataset dataset = ReadStationDataset(dataset_path);
    EXPECT_EQ(camera.ModelName(), "PINHOLE");
    EXPECT_TRUE(camera.has_prior_focal_length);
    EXPECT_NEAR(camera.params[0], dataset.rig.left.params[0], 1e-9);
    // COLMAP extracts in parallel, so image ids need not follow the names: compare the names as a set.
    std::set<std::string> names;
    for (const colmap::Image& image : database.ReadAllImages()) {
      names.insert(image.Name());
    }
    EXPECT_EQ(
        names,
        (std::set<std::string>{"left/000.png", "left/001.png", "left/002.png", "left/003.png"}));
    const ExtensionDatabase extension(db, ExtensionDatabase::Mode::kReadOnly);
    ASSERT_TRUE(extension.ReadRig());
    EXPECT_NEAR(extension.ReadRig()->BaselineMeters(), 0.38, 1e-9);
  }
  result = RunCommand(import);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(counts(), first) << "a second import changed the database";

  fs::create_directories(dir.File("sparse"));
  result = RunCommand(kColmap + " mapper --database_path " + db + " --image_path " + dataset_path +
                      "/images --output_path " + dir.File("sparse") + " --Mapper.num_threads 2" +
                      " --Mapper.ba_refine_focal_length 0");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  colmap::Reconstruction reconstruction;
  reconstruction.Read(dir.File("sparse/0"));
  EXPECT_EQ(reconstruction.NumRegImages(), 4u);
}

// 8 frames of the simulated street drive in dir/street (half-size images, sparse sweeps).
void SimulateStreet(const testing::ScopedTempDir& dir) {
  sim::SimulationOptions options;
  options.scene = "street";
  options.motion = sim::Motion::kDrive;
  options.output_path = dir.File("street");
  options.num_stations = 8;
  options.image_scale = 0.5;
  options.lidar_points = 5000;
  sim::SimulateDataset(options);
}

// Frames of a moving platform: `--matcher sequential` matches each frame with its successors only
// (every verified pair is consecutive by name), far fewer pairs than exhaustive matching; an unknown
// matcher is refused before anything is written.
TEST(FrontEndTest, SequentialMatcherPairsOnlyNeighbouringFrames) {
  testing::ScopedTempDir dir;
  SimulateStreet(dir);
  auto result = RunCommand(kCli + " import_dataset --dataset_path " + dir.File("street") +
                           " --database_path " + dir.File("seq.db") + kSift +
                           " --matcher sequential --SequentialMatching.overlap 3"
                           " --SequentialMatching.quadratic_overlap 0");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const colmap::Database database(dir.File("seq.db"));
  std::vector<std::pair<colmap::image_t, colmap::image_t>> pairs;
  std::vector<int> num_inliers;
  database.ReadTwoViewGeometryNumInliers(&pairs, &num_inliers);
  size_t num_verified = 0;
  for (size_t k = 0; k < pairs.size(); ++k) {
    const int a = std::stoi(fs::path(database.ReadImage(pairs[k].first).Name()).stem().string());
    const int b = std::stoi(fs::path(database.ReadImage(pairs[k].second).Name()).stem().string());
    EXPECT_LE(std::abs(a - b), 2) << a << "-" << b;
    num_verified += num_inliers[k] > 0;
  }
  std::cout << num_verified << " of " << pairs.size() << " pairs verified" << std::endl;
  // 7 consecutive and 6 second-neighbour pairs are attempted; measured: all 13 verified.
  EXPECT_GE(num_verified, 10u);
  EXPECT_LE(pairs.size(), 13u);

  result = RunCommand(kCli + " import_dataset --dataset_path " + dir.File("street") +
                      " --database_path " + dir.File("bad.db") + " --matcher vocab");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("matcher"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(dir.File("bad.db")));
}

// `--matcher spatial`: pose priors from a LiDAR registration folder (here written from the ground truth:
// frames 000-005 one component, 006-007 another with a world of its own), COLMAP's spatial matcher on
// them: every verified pair lies within the first component and is near in space; the other component
// gets no prior and so no pair.
TEST(FrontEndTest, SpatialMatcherPairsStationsNearInTheLidarRegistration) {
  testing::ScopedTempDir dir;
  SimulateStreet(dir);
  const auto cam_from_world = ReadNamedPoses(dir.File("street/ground_truth/cam_from_world.txt"));
  const colmap::Rigid3d cam_from_lidar =
      ReadPoseFile(dir.File("street/ground_truth/cam_from_lidar.txt"));
  std::map<std::string, colmap::Rigid3d> world_from_lidar;
  std::vector<LidarPairRecord> pairs;
  for (const auto& [station, pose] : cam_from_world) {
    world_from_lidar[station] = colmap::Inverse(pose) * cam_from_lidar;
  }
  for (int i = 0; i + 1 < 8; ++i) {
    if (i == 5) continue;  // two components: 000-005 and 006-007
    LidarPairRecord pair;
    pair.target = "00" + std::to_string(i);
    pair.source = "00" + std::to_string(i + 1);
    pairs.push_back(pair);
  }
  fs::create_directories(dir.File("lidar"));
  WriteLidarPairs(dir.File("lidar/pairs.txt"), pairs, {});
  WriteNamedPoses(dir.File("lidar/lidar_poses.txt"), "ground truth", world_from_lidar);
  const auto result = RunCommand(kCli + " import_dataset --dataset_path " + dir.File("street") +
                                 " --database_path " + dir.File("spatial.db") + kSift +
                                 " --matcher spatial --lidar_registration_path " +
                                 dir.File("lidar") + " --SpatialMatching.max_num_neighbors 3");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const colmap::Database database(dir.File("spatial.db"));
  EXPECT_EQ(database.NumPosePriors(), 6u);
  std::vector<std::pair<colmap::image_t, colmap::image_t>> image_pairs;
  std::vector<int> num_inliers;
  database.ReadTwoViewGeometryNumInliers(&image_pairs, &num_inliers);
  size_t num_verified = 0, num_unplaced_pairs = 0;
  bool unplaced_pair_verified = false;
  for (size_t k = 0; k < image_pairs.size(); ++k) {
    const auto frame = [&database](colmap::image_t id) {
      return std::stoi(fs::path(database.ReadImage(id).Name()).stem().string());
    };
    const int a = frame(image_pairs[k].first), b = frame(image_pairs[k].second);
    if (std::max(a, b) >= 6) {
      // 006 and 007 have no position: matched with every image, and with each other.
      ++num_unplaced_pairs;
      if (std::min(a, b) == 6) unplaced_pair_verified = num_inliers[k] > 0;
      continue;
    }
    EXPECT_LE(std::abs(a - b), 2) << a << "-" << b;
    num_verified += num_inliers[k] > 0;
  }
  std::cout << num_verified << " of " << image_pairs.size() - num_unplaced_pairs
            << " spatial pairs verified; " << num_unplaced_pairs
            << " pairs of the stations without a position" << std::endl;
  // Measured: 7 of 7 (each of the 6 frames with its 2 nearest); exhaustive matching would try 15.
  EXPECT_GE(num_verified, 6u);
  EXPECT_LE(image_pairs.size() - num_unplaced_pairs, 9u);
  // 006 with 000-005 and 007, 007 with 000-005; adjacent frames 006-007 share most of the view.
  EXPECT_EQ(num_unplaced_pairs, 13u);
  EXPECT_TRUE(unplaced_pair_verified);
}

// Bad stereo pairs: one clear error naming the station; the database is left exactly as it was.
TEST(FrontEndTest, BadInputNamesTheStationAndLeavesTheDatabaseUnchanged) {
  testing::ScopedTempDir dir;
  const std::string dataset_path = Simulate(dir, "dataset", 3, sim::Motion::kFixedRotation, 0.3);
  const std::string db = dir.File("db.db");
  ASSERT_EQ(RunCommand(kCli + " database_creator --database_path " + db).exit_code, 0);
  const std::string before = FileBytes(db);
  const std::string import =
      kCli + " import_dataset --dataset_path " + dataset_path + " --database_path " + db + kSift;
  const std::string stereo = kCli + " stereo_depth --dataset_path " + dataset_path +
                             " --output_path " + dir.File("stereo");
  const std::string right_001 = dataset_path + "/images/right/001.png";
  const std::string saved = FileBytes(right_001);
  auto expect_error = [&](const std::string& command, const std::vector<std::string>& needles) {
    const auto result = RunCommand(command);
    EXPECT_NE(result.exit_code, 0) << command;
    for (const std::string& needle : needles) {
      EXPECT_NE(result.output.find(needle), std::string::npos)
          << "'" << needle << "' not in: " << result.output;
    }
    EXPECT_EQ(FileBytes(db), before) << "the database changed: " << command;
    EXPECT_FALSE(fs::exists(db + ".import-partial"));
  };

  // Mismatched sizes.
  cv::Mat right = cv::imread(right_001);
  cv::Mat smaller;
  cv::resize(right, smaller, cv::Size(right.cols - 8, right.rows));
  cv::imwrite(right_001, smaller);
  expect_error(import, {"station 001", "right image"});
  expect_error(stereo, {"station 001"});
  EXPECT_FALSE(fs::exists(dir.File("stereo/stereo.json")));

  // Unreadable image.
  std::ofstream(right_001, std::ios::binary) << "not a png";
  expect_error(import, {"station 001", "cannot read"});
  expect_error(stereo, {"station 001", "cannot read"});

  // Missing right image.
  fs::remove(right_001);
  expect_error(import, {"001.png"});

  // Unknown camera model in rig.json.
  std::ofstream(right_001, std::ios::binary) << saved;
  const std::string rig = FileBytes(dataset_path + "/rig.json");
  std::string bad_rig = rig;
  const size_t at = bad_rig.find("PINHOLE");
  ASSERT_NE(at, std::string::npos);
  bad_rig.replace(at, 7, "PINHOLEX");
  std::ofstream(dataset_path + "/rig.json") << bad_rig;
  expect_error(import, {"rig.json", "PINHOLEX"});
  std::ofstream(dataset_path + "/rig.json") << rig;

  // The repaired dataset imports.
  const auto result = RunCommand(import);
  ASSERT_EQ(result.exit_code, 0) << result.output;

  // Depth maps of another rig (another image size) must not become priors at the wrong pixels.
  sim::SimulationOptions other;
  other.output_path = dir.File("other");
  other.num_stations = 2;
  other.motion = sim::Motion::kFixedRotation;
  other.image_scale = 0.2;
  other.lidar_points = 2000;
  sim::SimulateDataset(other);
  ASSERT_EQ(RunCommand(kCli + " stereo_depth --dataset_path " + other.output_path +
                       " --output_path " + dir.File("other_stereo"))
                .exit_code,
            0);
  const auto mismatch = RunCommand(kCli + " depth_prior_extractor --database_path " + db +
                                   " --depth_path " + dir.File("other_stereo"));
  EXPECT_NE(mismatch.exit_code, 0);
  EXPECT_NE(mismatch.output.find("belong to another dataset or rig"), std::string::npos)
      << mismatch.output;
  // No prior was written (COLMAP's own connection may rewrite the WAL header, so bytes are not compared).
  EXPECT_EQ(ExtensionDatabase(db, ExtensionDatabase::Mode::kReadOnly).NumDepthPriors(), 0u);
}

}  // namespace
}  // namespace colmap_lidar
