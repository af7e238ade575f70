#include "lidar/depth_discontinuities.h"

#include <gtest/gtest.h>

#include <cmath>

namespace colmap_lidar {
namespace {

// A sensor at the origin looking along +x at a wall at 10 m; a board at 6 m in front of it covers
// the azimuths of |y| < 1 m (at 6 m) and elevations of |z| < 1 m. Rays on a 0.2 deg grid.
std::vector<Eigen::Vector3d> BoardBeforeAWall() {
  std::vector<Eigen::Vector3d> points;
  const double step = 0.2 * M_PI / 180;
  for (double elevation = -0.3; elevation <= 0.3; elevation += step) {
    for (double azimuth = -0.5; azimuth <= 0.5; azimuth += step) {
      const Eigen::Vector3d ray(std::cos(elevation) * std::cos(azimuth),
                                std::cos(elevation) * std::sin(azimuth),
                                std::sin(elevation));
      const double to_board = 6.0 / ray.x();
      const Eigen::Vector3d on_board = to_board * ray;
      const bool hits_board = std::abs(on_board.y()) < 1.0 && std::abs(on_board.z()) < 1.0;
      points.push_back((hits_board ? to_board : 10.0 / ray.x()) * ray);
    }
  }
  return points;
}

TEST(DepthDiscontinuities, OnlyTheNearSideOfTheBoardsEdgesScores) {
  const std::vector<Eigen::Vector3d> points = BoardBeforeAWall();
  DepthDiscontinuityOptions options;
  options.angular_resolution_deg = 0.2;
  const std::vector<DepthDiscontinuity> edges = DetectDepthDiscontinuities(points, options);
  ASSERT_FALSE(edges.empty());
  int left = 0, right = 0;
  for (const DepthDiscontinuity& d : edges) {
    // On the board (6 m), at its border: the last cell of the row before the wall, 4 m further
    // (the top and bottom borders cross the rows of constant elevation too).
    EXPECT_NEAR(d.point_in_lidar.x(), 6.0, 1e-9);
    const Eigen::Vector3d& p = d.point_in_lidar;
    EXPECT_TRUE(std::abs(p.y()) > 1.0 - 0.025 || std::abs(p.z()) > 1.0 - 0.025) << p.transpose();
    // (the wall neighbour's ray is 0.2 deg off: its range differs by millimetres)
    EXPECT_NEAR(d.score, std::sqrt(p.norm() * (10.0 / 6.0 - 1.0)), 0.01);
    const double azimuth = std::atan2(p.y(), p.x());
    (azimuth < 0 ? left : right)++;
  }
  // The board is symmetric about the x axis (the ray grid nearly).
  EXPECT_LE(std::abs(left - right), 3);
  EXPECT_GT(left, 50);
  // Sorted by score, highest first.
  for (size_t k = 1; k < edges.size(); ++k) EXPECT_GE(edges[k - 1].score, edges[k].score);
}

TEST(DepthDiscontinuities, NoiseOnAFlatWallGivesNone) {
  std::vector<Eigen::Vector3d> points;
  const double step = 0.2 * M_PI / 180;
  uint32_t state = 1;
  for (double elevation = -0.3; elevation <= 0.3; elevation += step) {
    for (double azimuth = -0.5; azimuth <= 0.5; azimuth += step) {
      const Eigen::Vector3d ray(std::cos(elevation) * std::cos(azimuth),
                                std::cos(elevation) * std::sin(azimuth),
                                std::sin(elevation));
      state = state * 1664525u + 1013904223u;
      const double noise = 0.02 * (state / 4294967296.0 - 0.5);  // +-1 cm
      points.push_back((10.0 / ray.x() + noise) * ray);
    }
  }
  DepthDiscontinuityOptions options;
  options.angular_resolution_deg = 0.2;
  EXPECT_TRUE(DetectDepthDiscontinuities(points, options).empty());
  // A threshold of 0 keeps the noise's own steps: the detector does see them.
  options.min_score = 0.0;
  EXPECT_FALSE(DetectDepthDiscontinuities(points, options).empty());
}

TEST(DepthDiscontinuities, AutomaticResolutionAndMaxPoints) {
  const std::vector<Eigen::Vector3d> points = BoardBeforeAWall();
  DepthDiscontinuityOptions options;
  options.max_points = 10;
  const std::vector<DepthDiscontinuity> edges = DetectDepthDiscontinuities(points, options);
  ASSERT_EQ(edges.size(), 10u);
  for (const DepthDiscontinuity& d : edges) EXPECT_NEAR(d.point_in_lidar.x(), 6.0, 1e-9);
  options.gamma = 0;
  EXPECT_THROW(DetectDepthDiscontinuities(points, options), std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
