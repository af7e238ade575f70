// The data-derived registration gates: a cloud's own plane noise against its known range noise, and the
// constraint analysis of point-to-plane Hessians of a corridor (one free direction) and a room.
#include "lidar/registration_quality.h"

#include "lidar/pair_registration.h"
#include "lidar/point_to_plane_icp.h"
#include "lidar/station_cloud.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

namespace colmap_lidar {
namespace {

// A jittered scan of the plane z = 0 (one point per 5 cm cell), range noise sigma along z.
PointCloud NoisyPlane(double sigma, uint64_t seed) {
  PointCloud cloud;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0, sigma);
  std::uniform_real_distribution<double> jitter(0, 0.05);
  for (int a = 0; a < 200; ++a) {
    for (int b = 0; b < 200; ++b) {
      cloud.points.emplace_back(0.05 * a + jitter(rng), 0.05 * b + jitter(rng), noise(rng));
      cloud.normals.emplace_back(0, 0, 1);
    }
  }
  return cloud;
}

// What the gate relies on: a correct alignment of two scans of the same surface has an ICP RMSE close
// to the scans' own plane noise, whatever the noise level; and the noise estimate follows the noise.
TEST(PlaneNoiseRms, PredictsTheRmseOfACorrectAlignment) {
  double previous = 0;
  for (const double sigma : {0.002, 0.01, 0.02}) {
    const PointCloud source = NoisyPlane(sigma, 1), target = NoisyPlane(sigma, 2);
    const KdTree3 source_tree(source.points), target_tree(target.points);
    const double noise = PlaneNoiseRms(target, target_tree);
    EXPECT_GT(noise, 1.5 * previous);
    previous = noise;
    IcpOptions options;
    options.min_correspondence_distance = 0.1;
    const IcpResult icp =
        PointToPlaneIcp(source, target, target_tree, Eigen::Isometry3d::Identity(), options);
    const double ratio =
        icp.rmse /
        std::sqrt(0.5 * (noise * noise + std::pow(PlaneNoiseRms(source, source_tree), 2)));
    std::cout << "sigma " << sigma << ": plane noise " << noise << " m, ICP RMSE " << icp.rmse
              << " m, ratio " << ratio << std::endl;
    EXPECT_GT(ratio, 0.8);
    EXPECT_LT(ratio, 1.25);
  }
}

Eigen::Matrix<double, 6, 6> Hessian(
    const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& points_and_normals) {
  Eigen::Matrix<double, 6, 6> h = Eigen::Matrix<double, 6, 6>::Zero();
  for (const auto& [p, n] : points_and_normals) {
    Eigen::Matrix<double, 6, 1> j;
    j << p.cross(n), n;
    h += j * j.transpose();
  }
  return h;
}

std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> Corridor(bool with_end_wall) {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> samples;
  for (int a = -40; a <= 40; ++a) {
    for (int b = 0; b < 10; ++b) {
      const double y = 0.25 * a, z = 0.3 * b;
      samples.push_back({Eigen::Vector3d(-2, y, z), Eigen::Vector3d::UnitX()});
      samples.push_back({Eigen::Vector3d(2, y, z), -Eigen::Vector3d::UnitX()});
      samples.push_back({Eigen::Vector3d(0.1 * b - 0.5, y, -1.5), Eigen::Vector3d::UnitZ()});
      if (with_end_wall && a < -30) {
        samples.push_back({Eigen::Vector3d(0.4 * b - 2, 10, z), -Eigen::Vector3d::UnitY()});
      }
    }
  }
  return samples;
}

TEST(AnalyseConstraints, NamesTheFreeDirectionOfACorridor) {
  const ConstraintAnalysis corridor = AnalyseConstraints(Hessian(Corridor(false)), 5.0);
  EXPECT_LT(corridor.weakest_ratio, 1e-12);
  EXPECT_EQ(corridor.WeakestAxisName(), "ty");
  const ConstraintAnalysis room = AnalyseConstraints(Hessian(Corridor(true)), 5.0);
  EXPECT_GT(room.weakest_ratio, 1e-3);
  EXPECT_LT(room.weakest_ratio, 0.1);  // a short end wall holds y weakly, but holds it
  EXPECT_THROW(AnalyseConstraints(Hessian(Corridor(true)), 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar

namespace colmap_lidar {
namespace {

// Noise-free points of a room corner with a box: floor z = 0, walls x = 0 and y = 0, 5 cm grid.
PointCloud CleanRoom() {
  PointCloud cloud;
  for (int a = 0; a < 120; ++a) {
    for (int b = 0; b < 120; ++b) {
      const double u = 0.05 * a, v = 0.05 * b;
      cloud.points.emplace_back(u, v, 0);
      if (v < 3) cloud.points.emplace_back(0, u, v);
      if (v < 3) cloud.points.emplace_back(u, 0, v);
      if (u > 2 && u < 3 && v > 2 && v < 3) cloud.points.emplace_back(u, v, 1.0);
    }
  }
  return cloud;
}

// Exact synthetic clouds: the plane noise is then set by the folds between planes and the voxel grid
// (measured 2.2 mm), not near 0, so a correct alignment (RMSE 0.03 mm) passes the relative gate.
TEST(PairRegistrationGate, NoiseFreeCloudsPassTheRelativeGate) {
  StationCloudOptions cloud_options;
  cloud_options.compute_features = false;
  const PointCloud target_points = CleanRoom();
  Eigen::Isometry3d source_from_target = Eigen::Isometry3d::Identity();
  source_from_target.linear() =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d(0.3, -0.2, 1).normalized()).toRotationMatrix();
  source_from_target.translation() = Eigen::Vector3d(0.04, -0.03, 0.02);
  PointCloud source_points;
  for (const Eigen::Vector3d& p : target_points.points) {
    source_points.points.push_back(source_from_target * p);
  }
  const auto target = PrepareStationCloud(target_points, cloud_options);
  const auto source = PrepareStationCloud(source_points, cloud_options);
  PairRegistrationOptions options;
  const PairRegistration result = RegisterStationClouds(*source, *target, options);
  std::cout << "clean room: RMSE " << result.rmse << " m, plane noise " << result.noise_rms << " m"
            << std::endl;
  EXPECT_TRUE(result.accepted) << result.reason;
  EXPECT_GT(result.noise_rms, 1e-3);
  EXPECT_LT((result.target_from_source * source_from_target).translation().norm(), 1e-3);
}

}  // namespace
}  // namespace colmap_lidar
