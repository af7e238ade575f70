// Real HDL-64 sweeps: the KITTI raw sample in ../shared/data (not part of the repository; the test
// skips without it). Its six frames come from two places, as their camera images show: frames 1 and 34
// see the same building entrance from a standing car, frames 6, 19 and 35 the same square with walking
// people, frame 185 a third street. (README.md of the sample calls 34 and 35 consecutive; their images
// and clouds share nothing.) With default options the registration must group the sweeps by place,
// with the car's standstill as the relative motion, close the one 3-cycle, and refuse every pair across
// places.
#include "bridge/initialization/vertical_alignment.h"
#include "colmap_ext/kitti_calibration.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "lidar/station_cloud.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

namespace colmap_lidar {
namespace {

const std::string kSampleRoot =
    std::string(COLMAP_LIDAR_SHARED_DATA) + "/kitti_raw_2011_09_28_sample";
const std::string kSample = kSampleRoot + "/velodyne_points/data";

std::vector<Eigen::Vector3d> ReadKittiBin(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::vector<Eigen::Vector3d> points;
  float record[4];
  while (file.read(reinterpret_cast<char*>(record), sizeof(record))) {
    points.emplace_back(record[0], record[1], record[2]);
  }
  return points;
}

// Depth discontinuities along the sweep's scan order (Levinson and Thrun's X_i = max(r_{i-1} - r_i,
// r_{i+1} - r_i, 0)): the nearer point at a range jump of more than `min_jump_m`, within 30 m.
std::vector<Eigen::Vector3d> DepthEdgePoints(const std::vector<Eigen::Vector3d>& points,
                                             double min_jump_m) {
  std::vector<Eigen::Vector3d> edges;
  for (size_t i = 1; i + 1 < points.size(); ++i) {
    const double r = points[i].norm();
    const double jump = std::max({points[i - 1].norm() - r, points[i + 1].norm() - r, 0.0});
    if (jump > min_jump_m && r < 30) edges.push_back(points[i]);
  }
  return edges;
}

// Mean distance [px, capped at 10] from the projected depth-edge points to the nearest image edge.
double EdgeDistancePx(const std::vector<Eigen::Vector3d>& edge_points,
                      const colmap::Rigid3d& cam_from_velo,
                      const colmap::Camera& camera,
                      const cv::Mat& distance_to_edge) {
  double sum = 0;
  size_t count = 0;
  for (const Eigen::Vector3d& point : edge_points) {
    const Eigen::Vector3d point_in_cam = cam_from_velo * point;
    if (point_in_cam.z() < 1) continue;
    const Eigen::Vector2d xy = camera.ImgFromCam(point_in_cam.hnormalized());
    const int col = static_cast<int>(xy.x()), row = static_cast<int>(xy.y());
    if (col < 0 || row < 0 || col >= distance_to_edge.cols || row >= distance_to_edge.rows)
      continue;
    sum += std::min(10.f, distance_to_edge.at<float>(row, col));
    ++count;
  }
  return count > 0 ? sum / count : 10;
}

std::map<std::string, std::string> ReadSummary(const std::string& path) {
  std::map<std::string, std::string> values;
  std::ifstream file(path);
  std::string line;
  while (std::getline(file, line)) {
    const size_t space = line.find(' ');
    if (space != std::string::npos) values[line.substr(0, space)] += line.substr(space + 1) + ";";
  }
  return values;
}

TEST(KittiSampleTest, SweepsGroupByPlaceWithStandstillMotion) {
  if (!std::filesystem::is_directory(kSample)) {
    GTEST_SKIP() << "no KITTI sample at " << kSample;
  }
  testing::ScopedTempDir dir;
  const auto result =
      testing::RunCommand(std::string(COLMAP_LIDAR_CLI_EXE) + " lidar_registrator --lidar_path " +
                          kSample + " --output_path " + dir.File("out"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::cout << result.output.substr(result.output.find("stations"));
  const auto summary = ReadSummary(dir.File("out/summary.txt"));
  EXPECT_EQ(summary.at("components"), "3;");
  const std::string groups = summary.at("component");
  EXPECT_NE(groups.find("0: 0000000001 0000000034;"), std::string::npos) << groups;
  EXPECT_NE(groups.find("1: 0000000006 0000000019 0000000035;"), std::string::npos) << groups;
  EXPECT_NE(groups.find("2: 0000000185;"), std::string::npos) << groups;
  // Measured: 1.5 mm, 0.011 deg around 6-19-35.
  EXPECT_LT(std::stod(summary.at("worst_cycle_translation_m")), 0.005);
  EXPECT_LT(std::stod(summary.at("worst_cycle_rotation_deg")), 0.035);

  std::ifstream pairs(dir.File("out/pairs.txt"));
  std::string line;
  std::set<std::string> accepted;
  while (std::getline(pairs, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string target, source;
    double qw, qx, qy, qz, tx, ty, tz;
    fields >> target >> source >> qw >> qx >> qy >> qz >> tx >> ty >> tz;
    accepted.insert(target + "-" + source);
    // A standing car: measured at most 3.6 cm (sweep-to-sweep jitter) and 0.085 deg.
    EXPECT_LT(Eigen::Vector3d(tx, ty, tz).norm(), 0.11) << line;
    EXPECT_LT(Eigen::Quaterniond(qw, qx, qy, qz).angularDistance(Eigen::Quaterniond::Identity()) *
                  180 / M_PI,
              0.25)
        << line;
  }
  EXPECT_EQ(accepted,
            (std::set<std::string>{"0000000001-0000000034",
                                   "0000000006-0000000019",
                                   "0000000006-0000000035",
                                   "0000000019-0000000035"}));
}

// KITTI's published convention on real data: the sweeps' depth discontinuities, projected through the
// imported reference camera 0 (P_rect_00 R_rect_00 [R|T]), land on the image's edges. Scanning a rotation
// of the reference about each camera axis, the score is best within 0.5 deg of the reference and clearly
// worse 2 deg away (a wrong convention, e.g. without R_rect_00 or inverted, is degrees off).
TEST(KittiSampleTest, DepthEdgesProjectOntoImageEdgesThroughTheImportedCalibration) {
  if (!std::filesystem::is_directory(kSample)) {
    GTEST_SKIP() << "no KITTI sample at " << kSampleRoot;
  }
  // Through the product's importer: `import_kitti --camera 0` (a monocular dataset, 6 frames).
  testing::ScopedTempDir dir;
  const auto run =
      testing::RunCommand(std::string(COLMAP_LIDAR_CLI_EXE) + " import_kitti --kitti_path " +
                          kSampleRoot + " --calib_path " + kSampleRoot + "/calibration" +
                          " --output_path " + dir.File("dataset") + " --camera 0");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const StationDataset dataset = ReadStationDataset(dir.File("dataset"));
  ASSERT_EQ(dataset.stations.size(), 6u);
  EXPECT_FALSE(dataset.rig.IsStereo());
  EXPECT_FALSE(dataset.rig.cam_from_lidar_guess);
  KittiCamera camera;
  camera.camera = dataset.rig.left;
  camera.cam_from_velo = ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  std::vector<cv::Mat> distances;
  std::vector<std::vector<Eigen::Vector3d>> edge_points;
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    const cv::Mat image = cv::imread(dataset.LeftImagePath(i), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty()) << dataset.LeftImagePath(i);
    ASSERT_EQ(image.cols, static_cast<int>(camera.camera.width));
    cv::Mat edges;
    cv::Canny(image, edges, 100, 200);
    distances.emplace_back();
    cv::distanceTransform(255 - edges, distances.back(), cv::DIST_L2, 3);
    edge_points.push_back(DepthEdgePoints(ReadKittiBin(dataset.cloud_paths[i]), 0.5));
  }
  const auto score = [&](int axis, double degrees) {
    const colmap::Rigid3d rotated(
        Eigen::Quaterniond(Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d::Unit(axis))),
        Eigen::Vector3d::Zero());
    double total = 0;
    for (size_t k = 0; k < distances.size(); ++k) {
      total += EdgeDistancePx(
          edge_points[k], rotated * camera.cam_from_velo, camera.camera, distances[k]);
    }
    return total / distances.size();
  };
  const double reference = score(0, 0);
  for (int axis = 0; axis < 3; ++axis) {
    double best_degrees = 0, best = reference;
    std::cout << "camera axis "
              << "xyz"[axis] << ", mean distance of projected depth edges to image "
              << "edges [px] from -2 to 2 deg:";
    for (double degrees = -2; degrees <= 2.001; degrees += 0.25) {
      const double value = score(axis, degrees);
      std::cout << " " << std::setprecision(3) << value;
      if (value < best) best = value, best_degrees = degrees;
    }
    std::cout << std::endl;
    // Measured: best at -0.25 deg about x, at 0 about y and z; 2 deg away 0.23-1.2 px worse.
    EXPECT_LE(std::abs(best_degrees), 0.5) << "axis " << axis;
    EXPECT_GT(score(axis, -2), reference + 0.15) << "axis " << axis;
    EXPECT_GT(score(axis, 2), reference + 0.15) << "axis " << axis;
  }
}

}  // namespace
}  // namespace colmap_lidar

namespace colmap_lidar {
namespace {

// calibrate_edges (Levinson & Thrun's baseline) on the real sweeps and images: from import_kitti's
// seeded guess, 3 deg / 5 cm off KITTI's reference. Measured: rotation 0.36 deg, translation 108 mm
// (six frames; the translation moves a 15 m edge by 5 px per 10 cm and is not recovered: see
// docs/edge_calibration.md).
TEST(KittiSampleTest, EdgeCalibrationRecoversTheRotationFromAThreeDegreeGuess) {
  if (!std::filesystem::is_directory(kSample)) {
    GTEST_SKIP() << "no KITTI sample at " << kSampleRoot;
  }
  testing::ScopedTempDir dir;
  const std::string cli = COLMAP_LIDAR_CLI_EXE;
  const auto import = testing::RunCommand(
      cli + " import_kitti --kitti_path " + kSampleRoot + " --calib_path " + kSampleRoot +
      "/calibration" + " --output_path " + dir.File("dataset") + " --camera 0 --write_guess 1");
  ASSERT_EQ(import.exit_code, 0) << import.output;
  const auto run = testing::RunCommand(cli + " calibrate_edges --dataset_path " +
                                       dir.File("dataset") + " --output_path " + dir.File("edges"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const StationDataset dataset = ReadStationDataset(dir.File("dataset"));
  const colmap::Rigid3d reference = ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  const colmap::Rigid3d estimate = ReadPoseFile(dir.File("edges/cam_from_lidar.txt"));
  auto rotation_deg = [&](const colmap::Rigid3d& pose) {
    return reference.rotation.angularDistance(pose.rotation) * 180 / M_PI;
  };
  std::cout << "guess " << rotation_deg(*dataset.rig.cam_from_lidar_guess)
            << " deg; calibrate_edges " << rotation_deg(estimate) << " deg, "
            << (estimate.translation - reference.translation).norm() * 1000 << " mm" << std::endl;
  EXPECT_GT(rotation_deg(*dataset.rig.cam_from_lidar_guess), 2.5);
  EXPECT_LT(rotation_deg(estimate), 1.0);
  EXPECT_TRUE(std::filesystem::exists(dir.File("edges/report.json")));
}

}  // namespace
}  // namespace colmap_lidar

namespace colmap_lidar {
namespace {

// The vertical alignment (bridge/initialization/vertical_alignment.h) on the real sweeps and
// images, which needs no motion (the car stands). Measured at KITTI's reference: 0.71 and -1.04 deg on the two measured axes
// with sigmas of 1.2 and 1.0 deg. The six frames see three places; at the building entrance (frames
// 1 and 34) walls and image edges disagree by 1.2-1.3 deg, at the square the camera's vertical edges
// are few among slanted ones (fit RMS 5-7 deg). So on this sample the measurement is weak, and it
// must say so: its sigma must cover its error, and its result must hardly depend on the start (2 deg
// of roll about the optical axis and 0.5 deg of pitch).
TEST(KittiSampleTest, WallsAndVerticalEdgesGiveAnHonestTilt) {
  if (!std::filesystem::is_directory(kSample)) {
    GTEST_SKIP() << "no KITTI sample at " << kSampleRoot;
  }
  testing::ScopedTempDir dir;
  const auto import =
      testing::RunCommand(std::string(COLMAP_LIDAR_CLI_EXE) + " import_kitti --kitti_path " +
                          kSampleRoot + " --calib_path " + kSampleRoot +
                          "/calibration --output_path " + dir.File("dataset") + " --camera 0");
  ASSERT_EQ(import.exit_code, 0) << import.output;
  const StationDataset dataset = ReadStationDataset(dir.File("dataset"));
  const colmap::Rigid3d reference = ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  StationCloudOptions cloud_options;
  cloud_options.voxel_size = 0.1;  // as the joint adjuster's clouds
  cloud_options.compute_features = false;
  std::vector<std::unique_ptr<StationCloud>> clouds;
  std::vector<VerticalStationInput> inputs;
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    clouds.push_back(PrepareStationCloud(ReadStationCloud(dataset.cloud_paths[i]), cloud_options));
  }
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    inputs.push_back({dataset.stations[i],
                      dataset.LeftImagePath(i),
                      &dataset.rig.left,
                      &clouds[i]->cloud,
                      &clouds[i]->curvature});
  }
  const VerticalAlignmentOptions options;
  const Eigen::Quaterniond perturbation =
      Eigen::AngleAxisd(2.0 * M_PI / 180, Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d::UnitX());
  std::vector<Eigen::Quaterniond> results;
  for (const Eigen::Quaterniond& start :
       {reference.rotation, Eigen::Quaterniond(perturbation * reference.rotation)}) {
    const VerticalAlignment alignment =
        MeasureVerticalAlignment(inputs, start, Eigen::Vector3d::UnitZ(), options);
    ASSERT_TRUE(alignment.valid) << alignment.message;
    // The remaining error along the two measured axes, in their own sigmas.
    const Eigen::Quaterniond error = alignment.Corrected(start) * reference.rotation.inverse();
    const Eigen::AngleAxisd error_axis_angle(error);
    const Eigen::Vector2d error_on_axes =
        alignment.axes.transpose() * error_axis_angle.axis() * error_axis_angle.angle();
    const Eigen::Vector2d sigma = alignment.covariance.diagonal().cwiseSqrt();
    std::cout << alignment.message << "; error on the measured axes "
              << error_on_axes.transpose() * 180 / M_PI << " deg, sigma "
              << sigma.transpose() * 180 / M_PI << " deg" << std::endl;
    for (int k = 0; k < 2; ++k) {
      EXPECT_LT(std::abs(error_on_axes(k)), 2 * sigma(k)) << "axis " << k;
      EXPECT_LT(sigma(k) * 180 / M_PI, 3.0) << "axis " << k;
    }
    results.push_back(alignment.Corrected(start));
  }
  // Measured: 0.22 deg apart (the gates start from different guesses), a fifth of a sigma.
  EXPECT_LT(results[0].angularDistance(results[1]) * 180 / M_PI, 0.5);
}

}  // namespace
}  // namespace colmap_lidar
