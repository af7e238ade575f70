#include "lidar/extrinsic_alignment.h"

#include "tests/testing/camera_lidar_scene.h"
#include "tests/testing/car_cam_from_lidar.h"
#include "tests/testing/synthetic_clouds.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <random>

namespace colmap_lidar {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

Eigen::Isometry3d TrueCamFromLidar() { return testing::CarCamFromLidar(0.02); }

Eigen::Isometry3d Perturbation(double angle_deg,
                               const Eigen::Vector3d& axis,
                               const Eigen::Vector3d& t) {
  return Eigen::Translation3d(t) * Eigen::AngleAxisd(angle_deg / kRadToDeg, axis.normalized());
}

using Scene = testing::CameraLidarScene;

std::vector<Eigen::Isometry3d> FourStations() {
  return {Perturbation(0, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(-3, -1, 1.7)),
          Perturbation(60, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0.5, 1.7)),
          Perturbation(-120, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(2, -2, 1.7)),
          Perturbation(170, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(3, 1, 1.7))};
}

// `count` stations on a circle of 2 m, each turned to its own heading.
std::vector<Eigen::Isometry3d> StationsOnACircle(int count) {
  std::vector<Eigen::Isometry3d> stations;
  for (int i = 0; i < count; ++i) {
    const double angle = 2 * M_PI * i / count;
    stations.push_back(
        Perturbation(std::fmod(137.5 * i, 360.0),
                     Eigen::Vector3d::UnitZ(),
                     Eigen::Vector3d(2 * std::cos(angle), 1.5 * std::sin(angle), 1.7)));
  }
  return stations;
}

// Stations `world_from_lidar` inside `world` (a function of seed giving a sampled surface with
// normals): each sees one sampling of it with its LiDAR (1 cm noise) and another with its camera,
// whose depth error grows as d^2 / 700 m along the ray (a stereo pair with b f = 350 m px and 0.5 px
// disparity noise). With `station_error_deg` / `_m` > 0, each station's camera points also share one
// rigid error of their own (per axis, 1 sigma), as a stereo bias over a whole depth map would.
template <typename World>
Scene MakeScene(const World& world,
                uint32_t seed,
                const std::vector<Eigen::Isometry3d>& world_from_lidar = FourStations(),
                double station_error_deg = 0,
                double station_error_m = 0) {
  const Eigen::Isometry3d cam_from_lidar = TrueCamFromLidar();
  std::mt19937 rng(seed);
  std::normal_distribution<double> gaussian(0, 1);
  const auto draw = [&](double sigma) -> Eigen::Vector3d {
    return Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng)) * sigma;
  };
  StationCloudOptions cloud_options;
  cloud_options.compute_features = false;
  Scene scene;
  for (size_t i = 0; i < world_from_lidar.size(); ++i) {
    PointCloud lidar = world(seed * 100 + 2 * i, 0.01);
    for (Eigen::Vector3d& p : lidar.points) p = world_from_lidar[i].inverse() * p;
    lidar.normals.clear();
    scene.clouds.push_back(PrepareStationCloud(lidar, cloud_options));
    const Eigen::Vector3d rotation = draw(station_error_deg / kRadToDeg);
    const Eigen::Isometry3d station_error =
        Eigen::Translation3d(draw(station_error_m)) *
        Eigen::AngleAxisd(rotation.norm(), rotation.normalized());
    const Eigen::Isometry3d cam_from_world =
        station_error * cam_from_lidar * world_from_lidar[i].inverse();
    CameraDepthPoints camera;
    for (const Eigen::Vector3d& point_in_world : world(seed * 100 + 2 * i + 1, 0).points) {
      const Eigen::Vector3d p = cam_from_world * point_in_world;
      if (p.z() < 0.5 || std::abs(p.x()) > p.z() || std::abs(p.y()) > 0.6 * p.z()) continue;
      const double sigma = p.squaredNorm() / 700;
      camera.point_in_cam.push_back(p + sigma * gaussian(rng) * p.normalized());
      camera.sigma_along_ray_m.push_back(sigma);
    }
    scene.points.push_back(std::move(camera));
  }
  return scene;
}

PointCloud Room(uint32_t seed, double noise) { return testing::SyntheticRoom(150, seed, noise); }

// Only a floor: nothing fixes the position along it or the rotation about its normal.
PointCloud Floor(uint32_t seed, double noise) {
  std::mt19937 rng(seed);
  PointCloud cloud;
  testing::SampleBox({-8, -8, -0.01}, {8, 8, 0}, 100, false, &rng, &cloud);
  PointCloud top;
  std::normal_distribution<double> gaussian(0, noise > 0 ? noise : 1e-9);
  for (size_t k = 0; k < cloud.Size(); ++k) {
    if (cloud.normals[k].z() < 0.5) continue;
    top.points.push_back(cloud.points[k] + gaussian(rng) * cloud.normals[k]);
    top.normals.push_back(cloud.normals[k]);
  }
  return top;
}

void ExpectNear(const Eigen::Isometry3d& estimate,
                const Eigen::Isometry3d& truth,
                double max_deg,
                double max_m) {
  const Eigen::Isometry3d error = estimate * truth.inverse();
  std::cout << "error " << Eigen::AngleAxisd(error.linear()).angle() * kRadToDeg << " deg, "
            << (estimate.translation() - truth.translation()).norm() * 1000 << " mm" << std::endl;
  EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle() * kRadToDeg, max_deg);
  EXPECT_LT((estimate.translation() - truth.translation()).norm(), max_m);
}

TEST(ExtrinsicAlignmentTest, RecoversCamFromLidarFromDepthAloneWithoutMotion) {
  const Scene scene = MakeScene(Room, 1);
  const Eigen::Isometry3d truth = TrueCamFromLidar();
  const Eigen::Isometry3d start =
      Perturbation(3, Eigen::Vector3d(1, -1, 0.5), Eigen::Vector3d(0.12, -0.1, 0.15)) * truth;
  const ExtrinsicAlignmentResult result =
      AlignCameraPointsWithLidar(scene.points, scene.Clouds(), start, ExtrinsicAlignmentOptions());
  EXPECT_TRUE(result.converged) << result.iterations << " iterations";
  ExpectNear(result.cam_from_lidar, truth, 0.03, 0.006);  // measured 0.010 deg, 2.0 mm
  EXPECT_GT(result.num_associations, 0.8 * result.num_points);
  EXPECT_EQ(result.num_weak_directions, 0) << result.constraint_ratios.transpose();
  // Residuals in units of their own sigmas: the model of the noise is the simulated one.
  EXPECT_NEAR(result.rms_sigmas, 1.0, 0.3);
  EXPECT_LT(result.sigma_rotation_deg.maxCoeff(), 0.05);
  EXPECT_LT(result.sigma_translation_m.maxCoeff(), 0.005);
}

// How many of the 6 axis errors of `result` lie within 2 of its reported sigmas.
int WithinTwoSigmas(const ExtrinsicAlignmentResult& result, const Eigen::Isometry3d& truth) {
  const Eigen::AngleAxisd rotation(result.cam_from_lidar.linear() * truth.linear().transpose());
  const Eigen::Vector3d rotation_deg = rotation.angle() * rotation.axis() * kRadToDeg;
  const Eigen::Vector3d translation = result.cam_from_lidar.translation() - truth.translation();
  int within = 0;
  for (int axis = 0; axis < 3; ++axis) {
    within += std::abs(rotation_deg[axis]) <= 2 * result.sigma_rotation_deg[axis];
    within += std::abs(translation[axis]) <= 2 * result.sigma_translation_m[axis];
  }
  return within;
}

TEST(ExtrinsicAlignmentTest, ReportedSigmasCoverTheErrorOverSeededScenes) {
  const Eigen::Isometry3d truth = TrueCamFromLidar();
  int within = 0, total = 0;
  for (uint32_t seed = 10; seed < 22; ++seed) {
    const Scene scene = MakeScene(Room, seed);
    const ExtrinsicAlignmentResult result = AlignCameraPointsWithLidar(
        scene.points, scene.Clouds(), truth, ExtrinsicAlignmentOptions());
    EXPECT_FALSE(result.station_clustered);  // 4 stations: the formal covariance
    within += WithinTwoSigmas(result, truth);
    total += 6;
  }
  std::cout << within << " of " << total << " within 2 sigma" << std::endl;
  // 95 % of a Gaussian lies within 2 sigma; 72 draws.
  EXPECT_GE(within, 0.85 * total) << within << " of " << total;
}

// Errors shared by all points of a station (0.3 deg / 1 cm per station and axis) do not average out
// over its points: the formal covariance, which assumes they do, is far too small (measured: 0.005
// deg against errors of 0.1-0.3 deg), the covariance clustered by station is not. Without the depth
// scale's consider term, which would cover part of the errors by itself.
TEST(ExtrinsicAlignmentTest, StationClusteredSigmasCoverErrorsSharedWithinAStation) {
  const Eigen::Isometry3d truth = TrueCamFromLidar();
  ExtrinsicAlignmentOptions options;
  options.depth_scale_sigma = 0;
  ExtrinsicAlignmentOptions formal_options = options;
  formal_options.min_station_clusters = 1000;
  int within = 0, formal_within = 0, total = 0;
  for (uint32_t seed = 30; seed < 38; ++seed) {
    const Scene scene = MakeScene(Room, seed, StationsOnACircle(12), 0.3, 0.01);
    const ExtrinsicAlignmentResult result =
        AlignCameraPointsWithLidar(scene.points, scene.Clouds(), truth, options);
    EXPECT_TRUE(result.station_clustered);
    EXPECT_EQ(result.num_station_clusters, 12);
    within += WithinTwoSigmas(result, truth);
    formal_within += WithinTwoSigmas(
        AlignCameraPointsWithLidar(scene.points, scene.Clouds(), truth, formal_options), truth);
    total += 6;
  }
  std::cout << within << " of " << total << " within 2 clustered sigmas, " << formal_within
            << " within 2 formal sigmas" << std::endl;
  EXPECT_GE(within, 0.8 * total);
  EXPECT_LT(formal_within, 0.5 * total);
}

TEST(ExtrinsicAlignmentTest, DirectionsASingleFloorCannotFixStayAtTheStart) {
  const Scene scene = MakeScene(Floor, 3);
  const Eigen::Isometry3d truth = TrueCamFromLidar();
  // Off by a tilt (which the floor fixes) and along the floor (which it cannot see), in the LiDAR frame.
  const Eigen::Isometry3d start_lidar_from_cam =
      Perturbation(2, Eigen::Vector3d::UnitX(), Eigen::Vector3d(0.3, 0.2, 0)) * truth.inverse();
  const ExtrinsicAlignmentResult result = AlignCameraPointsWithLidar(
      scene.points, scene.Clouds(), start_lidar_from_cam.inverse(), ExtrinsicAlignmentOptions());
  const Eigen::Isometry3d lidar_from_cam = result.cam_from_lidar.inverse();
  // The tilt is recovered, and the camera's height above the floor.
  const Eigen::Vector3d up_in_cam = lidar_from_cam.linear().transpose() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d true_up_in_cam = truth.linear() * Eigen::Vector3d::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, up_in_cam.dot(true_up_in_cam))) * kRadToDeg, 0.1);
  const Eigen::Vector3d camera_offset =
      lidar_from_cam.translation() - truth.inverse().translation();
  EXPECT_LT(std::abs(camera_offset.z()), 0.005);
  // The offset along the floor stays where the start had it.
  EXPECT_NEAR(camera_offset.x(), 0.3, 0.01);
  EXPECT_NEAR(camera_offset.y(), 0.2, 0.01);
  // And the sigmas say which: the translation along the floor is known no better than the prior.
  EXPECT_EQ(result.num_weak_directions, 3) << result.constraint_ratios.transpose();
  EXPECT_GT(result.sigma_translation_m.maxCoeff(), 0.2);
}

}  // namespace
}  // namespace colmap_lidar
