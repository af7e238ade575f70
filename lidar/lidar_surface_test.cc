#include "lidar/lidar_surface.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

namespace colmap_lidar {
namespace {

const Eigen::Vector3d kNormal = Eigen::Vector3d(0.3, -0.2, -1.0).normalized();  // facing the camera

// A rotating LiDAR's scan lines on a plane 10 m in front of the camera (a facade seen from a car):
// lines `line_spacing_m` apart, a point every 2 cm along each, 1 cm range noise along the ray.
std::vector<Eigen::Vector3d> ScanLinesOnAPlane(int num_lines, double line_spacing_m) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.01);
  const Eigen::Vector3d centre(0, 0, 10);
  const Eigen::Vector3d along = kNormal.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d across = kNormal.cross(along);
  std::vector<Eigen::Vector3d> points;
  for (int line = 0; line < num_lines; ++line) {
    for (double s = -2; s <= 2; s += 0.02) {
      const Eigen::Vector3d on_plane =
          centre + s * along + (line - num_lines / 2) * line_spacing_m * across;
      points.push_back(on_plane * (1 + noise(rng) / on_plane.norm()));
    }
  }
  return points;
}

// Defect: with the 4 cm PCA radius alone, every sample of a drive's sweep (scan lines decimetres
// apart) had fewer than 8 neighbours and was dropped, and the mono densifier filled nothing.
TEST(LidarSurface, ScanLinesDecimetresApartGiveAPlaneWithItsNormal) {
  const std::vector<Eigen::Vector3d> points = ScanLinesOnAPlane(20, 0.15);
  LidarSurfaceOptions options;
  EXPECT_EQ(BuildLidarSurface(points, options).Size(), 0u);  // what the densifier had
  options.grow_sparse_neighbourhoods = true;
  const LidarSurface surface = BuildLidarSurface(points, options);
  double worst_deg = 0, mean_distance = 0;
  for (size_t i = 0; i < surface.Size(); ++i) {
    worst_deg =
        std::max(worst_deg, std::acos(std::min(1.0, surface.normals[i].dot(kNormal))) * 180 / M_PI);
    mean_distance += std::abs(kNormal.dot(surface.points[i] - Eigen::Vector3d(0, 0, 10)));
  }
  mean_distance /= std::max<size_t>(1, surface.Size());
  std::cout << surface.Size() << " of " << points.size() << " samples, normals within " << worst_deg
            << " deg, mean distance to the plane " << 1000 * mean_distance << " mm" << std::endl;
  // Measured: every sample, 4.4 deg at worst (the lines' ends), 1.4 mm.
  EXPECT_GT(surface.Size(), 0.9 * points.size());
  EXPECT_LT(worst_deg, 15.0);
  EXPECT_LT(mean_distance, 0.004);
}

// One scan line has no plane: every sample is dropped rather than given an arbitrary normal.
TEST(LidarSurface, ASingleScanLineIsDropped) {
  LidarSurfaceOptions options;
  options.grow_sparse_neighbourhoods = true;
  EXPECT_EQ(BuildLidarSurface(ScanLinesOnAPlane(1, 0.15), options).Size(), 0u);
}

TEST(LidarSurface, OptionsAreChecked) {
  LidarSurfaceOptions options;
  options.max_radius_m = 0.01;  // below radius_m
  EXPECT_FALSE(options.Check());
  options = LidarSurfaceOptions();
  options.min_planarity = 1;
  EXPECT_FALSE(options.Check());
}

}  // namespace
}  // namespace colmap_lidar
