// Self-consistency of the simulator's ground truth: what it writes must agree with itself, because every
// accuracy figure of the project is measured against it.
#include "bridge/simulation/renderer.h"
#include "bridge/simulation/scene.h"
#include "bridge/simulation/simulate_dataset.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "lidar/kd_tree.h"
#include "lidar/model_evaluation.h"
#include "lidar/util/statistics.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/mvs/depth_map.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

namespace colmap_lidar {
namespace {

double Bilinear(const cv::Mat& image, double x, double y) {
  // (x, y) in COLMAP's convention: pixel centres at +0.5.
  const double u = x - 0.5, v = y - 0.5;
  const int u0 = static_cast<int>(std::floor(u)), v0 = static_cast<int>(std::floor(v));
  if (u0 < 0 || v0 < 0 || u0 + 1 >= image.cols || v0 + 1 >= image.rows) return -1;
  const double a = u - u0, b = v - v0;
  auto at = [&](int r, int c) { return static_cast<double>(image.at<uint8_t>(r, c)); };
  return (1 - a) * (1 - b) * at(v0, u0) + a * (1 - b) * at(v0, u0 + 1) +
         (1 - a) * b * at(v0 + 1, u0) + a * b * at(v0 + 1, u0 + 1);
}

sim::SimulationOptions NoiseFreeOptions(const std::string& scene, const std::string& output_path) {
  sim::SimulationOptions options;
  options.scene = scene;
  options.output_path = output_path;
  options.num_stations = 3;
  options.lidar_points = 30000;
  options.range_noise_m = 0;
  options.pixel_noise = 0;
  options.surface_spacing_m = 0.01;
  options.image_scale = 0.25;
  return options;
}

// The scenes scanned from tripod stations (the street is driven: DriveSweeps... below).
std::vector<std::string> StationSceneNames() {
  std::vector<std::string> names = sim::Scene::Names();
  names.erase(std::remove(names.begin(), names.end(), "street"), names.end());
  return names;
}

class SimulatorSceneTest : public ::testing::TestWithParam<std::string> {};

TEST_P(SimulatorSceneTest, LidarPointsLandOnTheTrueSurface) {
  testing::ScopedTempDir dir;
  const std::string root = dir.File("dataset");
  const sim::SimulationOptions options = NoiseFreeOptions(GetParam(), root);
  const sim::SimulationResult result = sim::SimulateDataset(options);
  EXPECT_EQ(result.num_stations, 3);
  const StationDataset dataset = ReadStationDataset(root);
  ASSERT_EQ(dataset.stations.size(), 3u);
  const auto cam_from_world = ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt"));
  const colmap::Rigid3d cam_from_lidar =
      ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  const PointCloud surface = ReadPointCloud(dataset.GroundTruthPath("surface.ply"));
  ASSERT_TRUE(surface.HasNormals());
  const KdTree3 tree(surface.points);
  const sim::Scene scene = sim::Scene::Create(GetParam());

  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    const PointCloud cloud = ReadPointCloud(dataset.cloud_paths[i]);
    // world_from_lidar = inverse(cam_from_world) * cam_from_lidar
    const colmap::Rigid3d world_from_lidar =
        colmap::Inverse(cam_from_world.at(dataset.stations[i])) * cam_from_lidar;
    size_t num_on_object = 0;
    double max_distance = 0;
    for (const Eigen::Vector3d& point_in_lidar : cloud.points) {
      const Eigen::Vector3d point_in_world = world_from_lidar * point_in_lidar;
      // Near the structure but not on the ground around its base (surface.ply has no ground).
      if (!scene.InsideObject(point_in_world, 0.01) || point_in_world.z() < 0.01) {
        continue;
      }
      ++num_on_object;
      max_distance = std::max(
          max_distance,
          DistanceToSampledSurface(surface, tree, options.surface_spacing_m, point_in_world));
    }
    EXPECT_GT(num_on_object, 200u) << "station " << i;
    // Float32 storage of the clouds (~1e-6 m) is the only error left with noise off: sub-mm.
    EXPECT_LT(max_distance, 1e-4) << "station " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(AllScenes, SimulatorSceneTest, ::testing::ValuesIn(StationSceneNames()));

// Full-resolution, noise-free images of two stations of each scene (the texture is not aliased there).
class SimulatorImageTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    sim::SimulationOptions options = NoiseFreeOptions(GetParam(), dir_.File("d"));
    options.num_stations = 2;
    options.lidar_points = 2000;
    options.image_scale = 1.0;
    options.surface_spacing_m = 0.004;
    sim::SimulateDataset(options);
    dataset_ = ReadStationDataset(dir_.File("d"));
  }
  testing::ScopedTempDir dir_;
  StationDataset dataset_;
};

TEST_P(SimulatorImageTest, ProjectedSurfacePointsShowTheirTextureAndDepth) {
  const auto cam_from_world = ReadNamedPoses(dataset_.GroundTruthPath("cam_from_world.txt"));
  const PointCloud surface = ReadPointCloud(dataset_.GroundTruthPath("surface.ply"));
  const sim::Scene scene = sim::Scene::Create(GetParam());
  const colmap::Camera& camera = dataset_.rig.left;
  for (size_t i = 0; i < dataset_.stations.size(); ++i) {
    const cv::Mat image = cv::imread(dataset_.LeftImagePath(i), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty());
    colmap::mvs::DepthMap depth;
    depth.Read(dataset_.GroundTruthPath("depth/" + dataset_.stations[i] + ".bin"));
    ASSERT_EQ(depth.GetWidth(), camera.width);
    const colmap::Rigid3d& pose = cam_from_world.at(dataset_.stations[i]);
    // A pose 5 mm off, as a control: the same comparison must then fail clearly.
    colmap::Rigid3d shifted = pose;
    shifted.translation.x() += 0.005;
    std::vector<double> texture_errors, shifted_errors, depth_errors;
    const Eigen::Vector3d center = colmap::Inverse(pose).translation;
    for (size_t k = 0; k < surface.Size(); k += 3) {
      const Eigen::Vector3d& point = surface.points[k];
      const Eigen::Vector3d point_in_cam = pose * point;
      if (point_in_cam.z() < 0.1) continue;
      const Eigen::Vector2d xy = camera.ImgFromCam(point_in_cam.hnormalized());
      if (xy.x() < 2 || xy.y() < 2 || xy.x() > camera.width - 2 || xy.y() > camera.height - 2) {
        continue;
      }
      // Visible: the first hit from the camera centre towards the point is the point itself.
      sim::RayHit hit;
      const Eigen::Vector3d ray = (point - center).normalized();
      if (!scene.Intersect(center, ray, 1e3, &hit) ||
          std::abs(hit.t - (point - center).norm()) > 1e-6) {
        continue;
      }
      // Away from silhouettes, where a pixel sees two surfaces.
      if (std::abs(surface.normals[k].dot(ray)) < 0.3) continue;
      const double expected = scene.Shade(point, hit.normal, hit.primitive);
      texture_errors.push_back(std::abs(Bilinear(image, xy.x(), xy.y()) - expected));
      const Eigen::Vector2d xy_shifted = camera.ImgFromCam((shifted * point).hnormalized());
      shifted_errors.push_back(
          std::abs(Bilinear(image, xy_shifted.x(), xy_shifted.y()) - expected));
      const float z = depth.Get(static_cast<size_t>(xy.y()), static_cast<size_t>(xy.x()));
      depth_errors.push_back(std::abs(z - point_in_cam.z()));
    }
    ASSERT_GT(texture_errors.size(), 1000u) << "station " << i;
    // Bilinear interpolation of a texture with 1 cm detail at ~2 mm pixels: a few grey levels.
    EXPECT_LT(Median(texture_errors), 4.0) << "station " << i;
    EXPECT_GT(Median(shifted_errors), 2.5 * Median(texture_errors)) << "station " << i;
    // Nearest-pixel depth on a slanted face: within a pixel footprint (~2 mm at 2.5 m).
    EXPECT_LT(Median(depth_errors), 0.002) << "station " << i;
  }
}

TEST_P(SimulatorImageTest, LeftAndRightImagesAgreeThroughTheTrueDepthAndBaseline) {
  const StationRig& rig = dataset_.rig;
  EXPECT_NEAR(rig.BaselineMeters(), 0.38, 1e-9);
  for (size_t i = 0; i < dataset_.stations.size(); ++i) {
    const cv::Mat left = cv::imread(dataset_.LeftImagePath(i), cv::IMREAD_GRAYSCALE);
    const cv::Mat right = cv::imread(dataset_.RightImagePath(i), cv::IMREAD_GRAYSCALE);
    colmap::mvs::DepthMap depth;
    depth.Read(dataset_.GroundTruthPath("depth/" + dataset_.stations[i] + ".bin"));
    colmap::Rigid3d wrong_baseline = rig.right_from_left;
    wrong_baseline.translation *= 0.4 / 0.38;
    std::vector<double> errors, wrong_errors;
    for (size_t row = 4; row < depth.GetHeight() - 4; row += 3) {
      for (size_t col = 4; col < depth.GetWidth() - 4; col += 3) {
        const double z = depth.Get(row, col);
        if (z <= 0 || z > 6) continue;  // the structure and the ground near it
        const Eigen::Vector3d point_in_left =
            z * rig.left.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5)).homogeneous();
        const double value = left.at<uint8_t>(row, col);
        const Eigen::Vector2d in_right =
            rig.right->ImgFromCam((rig.right_from_left * point_in_left).hnormalized());
        const Eigen::Vector2d in_right_wrong =
            rig.right->ImgFromCam((wrong_baseline * point_in_left).hnormalized());
        const double r = Bilinear(right, in_right.x(), in_right.y());
        const double w = Bilinear(right, in_right_wrong.x(), in_right_wrong.y());
        if (r < 0 || w < 0) continue;
        errors.push_back(std::abs(r - value));
        wrong_errors.push_back(std::abs(w - value));
      }
    }
    ASSERT_GT(errors.size(), 5000u);
    EXPECT_LT(Median(errors), 4.0) << "station " << i;
    EXPECT_GT(Median(wrong_errors), 2.5 * Median(errors)) << "station " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(AllScenes, SimulatorImageTest, ::testing::ValuesIn(StationSceneNames()));

std::string FileBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), {});
}

// Mean absolute grey-level difference of two images over the pixels where `depth` has a hit.
double MeanAbsoluteDifference(const cv::Mat& a, const cv::Mat& b, const cv::Mat& depth) {
  double sum = 0;
  int count = 0;
  for (int row = 0; row < a.rows; ++row) {
    for (int col = 0; col < a.cols; ++col) {
      if (depth.at<float>(row, col) <= 0) continue;
      sum += std::abs(a.at<uint8_t>(row, col) - b.at<uint8_t>(row, col));
      ++count;
    }
  }
  return count > 0 ? sum / count : 0;
}

// The road ahead of a car camera, 10-40 m away, rendered noise-free with 1 and 4 x 4 rays per
// pixel, against the pixel's area integrated with 8 x 8. One ray aliases the road's centimetre
// texture (a pixel row covers decimetres of road there): its grey levels are far from the pixel's
// mean; 4 x 4 comes close to it.
TEST(SimulatorTest, PixelSamplesRemoveTheRoadsAliasing) {
  const sim::Scene scene = sim::Scene::Create("street");
  // The band of a 1242 x 375 image (f 621 px) 10-40 m ahead: full-image rows 213-290
  // (1.65 m * 621 / (row - 187.5)), within 150 px of the centre column.
  colmap::Camera camera = colmap::Camera::CreateFromModelName(1, "PINHOLE", 621, 300, 78);
  camera.params = {621, 621, 150, 187.5 - 213};
  Eigen::Matrix3d world_from_cam_rotation;  // looking along the street (+x), camera y down
  world_from_cam_rotation.col(0) = -Eigen::Vector3d::UnitY();
  world_from_cam_rotation.col(1) = -Eigen::Vector3d::UnitZ();
  world_from_cam_rotation.col(2) = Eigen::Vector3d::UnitX();
  const colmap::Rigid3d cam_from_world = colmap::Inverse(colmap::Rigid3d(
      Eigen::Quaterniond(world_from_cam_rotation), Eigen::Vector3d(0, -1.79, 1.65)));
  sim::ImageOptions options;
  options.pixel_noise = 0;
  cv::Mat depth;
  const cv::Mat one_ray = sim::RenderImage(scene, camera, cam_from_world, options, &depth);
  options.samples_per_axis = 4;
  const cv::Mat four = sim::RenderImage(scene, camera, cam_from_world, options, nullptr);
  options.samples_per_axis = 8;
  const cv::Mat area = sim::RenderImage(scene, camera, cam_from_world, options, nullptr);
  const double one_ray_error = MeanAbsoluteDifference(one_ray, area, depth);
  const double four_error = MeanAbsoluteDifference(four, area, depth);
  std::cout << "mean |grey - area mean|: 1 ray " << one_ray_error << ", 4 x 4 rays " << four_error
            << std::endl;
  EXPECT_GT(one_ray_error, 5.0);
  EXPECT_LT(four_error, 0.5 * one_ray_error);
}

TEST(SimulatorTest, DeterministicForAGivenSeed) {
  testing::ScopedTempDir dir;
  sim::SimulationOptions options = NoiseFreeOptions("cylinder_pillar", dir.File("a"));
  options.range_noise_m = 0.01;
  options.pixel_noise = 1.0;
  options.num_stations = 2;
  sim::SimulateDataset(options);
  options.output_path = dir.File("b");
  sim::SimulateDataset(options);
  options.output_path = dir.File("c");
  options.seed = 1;
  sim::SimulateDataset(options);
  for (const char* file : {"/lidar/001.pcd", "/images/left/001.png", "/rig.json"}) {
    EXPECT_EQ(FileBytes(dir.File("a") + file), FileBytes(dir.File("b") + file)) << file;
    EXPECT_NE(FileBytes(dir.File("a") + file), FileBytes(dir.File("c") + file)) << file;
  }
}

TEST(SimulatorTest, MixedEdgePointsFloatBetweenSurfaces) {
  testing::ScopedTempDir dir;
  sim::SimulationOptions options = NoiseFreeOptions("square_pillar", dir.File("d"));
  options.num_stations = 2;
  options.lidar_points = 60000;
  options.mixed_edge_points = true;
  sim::SimulateDataset(options);
  const StationDataset dataset = ReadStationDataset(dir.File("d"));
  const auto cam_from_world = ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt"));
  const colmap::Rigid3d cam_from_lidar =
      ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  const sim::Scene scene = sim::Scene::Create("square_pillar");
  const PointCloud cloud = ReadPointCloud(dataset.cloud_paths[0]);
  const colmap::Rigid3d world_from_lidar =
      colmap::Inverse(cam_from_world.at(dataset.stations[0])) * cam_from_lidar;
  // A point on a surface is hit by the ray through it at its own range; a mixed point lies in front of
  // or behind the first surface along its ray by more than a few centimetres.
  size_t num_mixed = 0;
  for (const Eigen::Vector3d& point_in_lidar : cloud.points) {
    const Eigen::Vector3d ray = world_from_lidar.rotation * point_in_lidar.normalized();
    sim::RayHit hit;
    if (scene.Intersect(world_from_lidar.translation, ray, 200, &hit) &&
        std::abs(hit.t - point_in_lidar.norm()) > 0.05) {
      ++num_mixed;
    }
  }
  EXPECT_GT(num_mixed, 20u);
  EXPECT_LT(num_mixed, cloud.Size() / 20) << "only edge returns are mixed";
}

TEST(SimulatorTest, RefusesToOverwriteAndLeavesNoPartialOutput) {
  testing::ScopedTempDir dir;
  sim::SimulationOptions options = NoiseFreeOptions("square_pillar", dir.File("d"));
  options.num_stations = 2;
  sim::SimulateDataset(options);
  EXPECT_THROW(sim::SimulateDataset(options), std::runtime_error);
  options.scene = "no_such_scene";
  options.overwrite = true;
  EXPECT_THROW(sim::SimulateDataset(options), std::invalid_argument);
  EXPECT_TRUE(std::filesystem::exists(dir.File("d/rig.json")))
      << "a failed run must not destroy the previous dataset";
  EXPECT_FALSE(std::filesystem::exists(dir.File("d.partial")));
}

TEST(SimulatorTest, GuessIsTheTruthPerturbedByTheDocumentedAmount) {
  testing::ScopedTempDir dir;
  sim::SimulationOptions options = NoiseFreeOptions("t_specimen", dir.File("d"));
  options.num_stations = 2;
  sim::SimulateDataset(options);
  const StationDataset dataset = ReadStationDataset(dir.File("d"));
  ASSERT_TRUE(dataset.rig.cam_from_lidar_guess.has_value());
  const colmap::Rigid3d truth = ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  const colmap::Rigid3d& guess = *dataset.rig.cam_from_lidar_guess;
  EXPECT_NEAR(guess.rotation.angularDistance(truth.rotation) * 180 / M_PI, 3.0, 1e-6);
  EXPECT_NEAR((guess.translation - truth.translation).norm(), 0.05, 1e-9);
}

}  // namespace
}  // namespace colmap_lidar

namespace colmap_lidar {
namespace {

// A sweep's point was fired at the fraction of the sweep its azimuth gives (the sweep starts facing
// backwards): tau = (azimuth - 180 deg) / 360 deg, wrapped into [0, 1).
double FiringFraction(const Eigen::Vector3d& point_in_lidar) {
  const double tau = (std::atan2(point_in_lidar.y(), point_in_lidar.x()) - M_PI) / (2 * M_PI);
  return tau < 0 ? tau + 1 : tau;
}

// The driving scene, noise off: each sweep point moved to the world with the pose of its own firing
// instant (the frame pose at mid-sweep, the neighbouring frames at the ends) has the depth the camera's
// true depth map shows for it, while the same points taken with the frame pose alone (no motion
// compensation, as registration sees them) are displaced by up to half a frame's travel.
TEST(SimulatorTest, DriveSweepsAgreeWithTheImagesAtTheirFiringInstant) {
  testing::ScopedTempDir dir;
  sim::SimulationOptions options = NoiseFreeOptions("street", dir.File("d"));
  options.motion = sim::Motion::kDrive;
  options.num_stations = 4;
  options.lidar_points = 60000;
  options.image_scale = 0.5;
  sim::SimulateDataset(options);
  const StationDataset dataset = ReadStationDataset(dir.File("d"));
  EXPECT_EQ(dataset.rig.left.width, 621u);
  EXPECT_EQ(dataset.rig.left.height, 188u);
  // rig.json says the clouds are sweeps (the pipeline then de-skews them), as import_kitti does.
  ASSERT_TRUE(dataset.rig.lidar_sweep);
  EXPECT_EQ(dataset.rig.lidar_sweep->start_azimuth_deg, 180.0);
  const auto cam_from_world = ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt"));
  const colmap::Rigid3d cam_from_lidar =
      ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  std::vector<colmap::Rigid3d> world_from_lidar;
  for (const std::string& station : dataset.stations) {
    world_from_lidar.push_back(colmap::Inverse(cam_from_world.at(station)) * cam_from_lidar);
  }
  const size_t i = 1;  // a frame with both neighbours
  const PointCloud cloud = ReadPointCloud(dataset.cloud_paths[i]);
  colmap::mvs::DepthMap depth;
  depth.Read(dataset.GroundTruthPath("depth/" + dataset.stations[i] + ".bin"));
  std::vector<double> errors, displacements;
  for (const Eigen::Vector3d& point_in_lidar : cloud.points) {
    const double tau = FiringFraction(point_in_lidar);
    const colmap::Rigid3d fired =
        tau < 0.5 ? sim::Interpolate(world_from_lidar[i - 1], world_from_lidar[i], 0.5 + tau)
                  : sim::Interpolate(world_from_lidar[i], world_from_lidar[i + 1], tau - 0.5);
    const Eigen::Vector3d point_in_world = fired * point_in_lidar;
    displacements.push_back((world_from_lidar[i] * point_in_lidar - point_in_world).norm());
    const Eigen::Vector3d point_in_cam = cam_from_world.at(dataset.stations[i]) * point_in_world;
    if (point_in_cam.z() < 1) continue;
    const Eigen::Vector2d xy = dataset.rig.left.ImgFromCam(point_in_cam.hnormalized());
    if (xy.x() < 1 || xy.y() < 1 || xy.x() >= depth.GetWidth() - 1 ||
        xy.y() >= depth.GetHeight() - 1) {
      continue;
    }
    errors.push_back(std::abs(depth.Get(static_cast<size_t>(xy.y()), static_cast<size_t>(xy.x())) -
                              point_in_cam.z()) /
                     point_in_cam.z());
  }
  ASSERT_GT(errors.size(), 2000u);
  // Pixel quantisation of the depth lookup across slanted surfaces, not pose error: measured 0.19 %.
  EXPECT_LT(Median(errors), 0.006);
  const double max_displacement = *std::max_element(displacements.begin(), displacements.end());
  const double travel =
      (world_from_lidar[i + 1].translation - world_from_lidar[i - 1].translation).norm();
  std::cout << "median relative depth error " << Median(errors)
            << ", uncompensated displacement up to " << max_displacement << " m (travel " << travel
            << " m over two frames)" << std::endl;
  EXPECT_GT(max_displacement, 0.2 * travel);
}

// A straight drive never turns: every frame has the same orientation, the camera centres advance
// along world x by 0.5-1 m at one height and lateral offset. The drive with turns is the control.
TEST(SimulatorTest, StraightDriveHasNoRelativeRotation) {
  const sim::Scene scene = sim::Scene::Create("street");
  const auto max_turn_deg = [&](sim::Motion motion) {
    const std::vector<colmap::Rigid3d> frames = sim::MakeStations(scene, 40, motion, 7);
    double turn = 0;
    for (const colmap::Rigid3d& frame : frames) {
      turn = std::max(turn, frame.rotation.angularDistance(frames.front().rotation) * 180 / M_PI);
    }
    return turn;
  };
  EXPECT_LT(max_turn_deg(sim::Motion::kStraightDrive), 1e-9);
  EXPECT_GT(max_turn_deg(sim::Motion::kDrive), 1.0);
  const std::vector<colmap::Rigid3d> frames =
      sim::MakeStations(scene, 40, sim::Motion::kStraightDrive, 7);
  for (size_t i = 1; i < frames.size(); ++i) {
    const Eigen::Vector3d step =
        colmap::Inverse(frames[i]).translation - colmap::Inverse(frames[i - 1]).translation;
    EXPECT_NEAR(step.y(), 0, 1e-9);
    EXPECT_NEAR(step.z(), 0, 1e-9);
    EXPECT_GE(step.x(), 0.5);
    EXPECT_LE(step.x(), 1.0);
  }
}

}  // namespace
}  // namespace colmap_lidar
