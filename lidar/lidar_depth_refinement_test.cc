#include "lidar/lidar_depth_refinement.h"

#include <gtest/gtest.h>

#include <random>

namespace colmap_lidar {
namespace {

// A step edge seen by a camera at the origin (camera frame: x right, y down, z forward): a slanted
// foreground plate z = 2 - 0.2 x for x < 0, and a background wall z = 2.4 behind it.
constexpr double kWallZ = 2.4;
double ForegroundZ(double x) { return 2.0 - 0.2 * x; }

PinholeIntrinsics Camera() {
  PinholeIntrinsics intrinsics;
  intrinsics.width = 240;
  intrinsics.height = 160;
  intrinsics.fx = intrinsics.fy = 240;
  intrinsics.cx = 120;
  intrinsics.cy = 80;
  return intrinsics;
}

// True depth along a pixel's ray: the plate where the ray meets it at x < 0, else the wall.
double TrueDepth(const PinholeIntrinsics& intrinsics, int col, int row) {
  const Eigen::Vector3d ray = intrinsics.PixelRay(col, row);
  const double z = 2.0 / (1 + 0.2 * ray.x());  // ray meets the plate's plane
  return ray.x() * z < 0 ? z : kWallZ;
}

// What a LiDAR 0.2 m to the camera's right sees, on a 6 mm grid with 1 mm noise: the plate, and the
// wall except the plate's shadow. It sees a strip of wall behind the plate's edge that the camera
// does not: those samples project onto the plate's pixels and must stay hidden.
std::vector<Eigen::Vector3d> LidarPoints() {
  const Eigen::Vector3d lidar(0.2, 0, 0);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.001);
  std::vector<Eigen::Vector3d> points;
  for (double y = -0.9; y <= 0.9; y += 0.006) {
    for (double x = -1.4; x <= 1.4; x += 0.006) {
      if (x < 0) points.emplace_back(x, y, ForegroundZ(x) + noise(rng));
      // Wall point: hidden when the segment to the LiDAR crosses the plate.
      const Eigen::Vector3d wall(x, y, kWallZ);
      const Eigen::Vector3d d = wall - lidar;
      // Intersection with the plate's plane z = 2 - 0.2 x along lidar + t d.
      const double t = (2.0 - 0.2 * lidar.x() - lidar.z()) / (d.z() + 0.2 * d.x());
      const bool hidden = t > 0 && t < 1 && (lidar + t * d).x() < 0;
      if (!hidden) points.emplace_back(x, y, kWallZ + noise(rng));
    }
  }
  return points;
}

TEST(LidarDepthRefinement, RemovesWrongStereoAndFillsHolesWithoutCrossingTheStepEdge) {
  const PinholeIntrinsics intrinsics = Camera();
  LidarSurfaceOptions surface_options;
  surface_options.sample_spacing_m = 0.006;
  surface_options.radius_m = 0.03;
  surface_options.curvature_radius_m = 0.06;
  const LidarSurface surface = BuildLidarSurface(LidarPoints(), surface_options);
  ASSERT_GT(surface.Size(), 10000u);

  DepthImage truth(intrinsics.height, intrinsics.width);
  for (int row = 0; row < intrinsics.height; ++row) {
    for (int col = 0; col < intrinsics.width; ++col) {
      truth(row, col) = float(TrueDepth(intrinsics, col, row));
    }
  }
  const int edge_col = 120;  // first wall column
  ASSERT_GT(truth(80, edge_col - 1), 0);
  ASSERT_LT(truth(80, edge_col - 1), 2.01);
  ASSERT_FLOAT_EQ(truth(80, edge_col), float(kWallZ));

  DepthImage stereo = truth;
  // A hole inside the plate, a hole band across the edge, foreground fattening onto the wall (the
  // typical stereo error at a depth edge) and scattered outliers 3 cm off.
  stereo.block(20, 30, 30, 40).setZero();
  stereo.block(60, 100, 40, 40).setZero();
  for (int row = 110; row < 140; ++row) {
    for (int col = edge_col; col < edge_col + 4; ++col) stereo(row, col) = 2.0f;
  }
  std::mt19937 rng(5);
  std::vector<std::pair<int, int>> outliers;
  for (int k = 0; k < 200; ++k) {
    const int row = std::uniform_int_distribution<int>(0, 159)(rng);
    const int col = std::uniform_int_distribution<int>(0, 239)(rng);
    if (stereo(row, col) > 0) {
      stereo(row, col) += 0.03f;
      outliers.emplace_back(row, col);
    }
  }

  const LidarDepthRefinementOptions options;
  const RefinedDepth refined = RefineDepthWithLidar(stereo, surface, intrinsics, options);

  // Fold 1: every outlier and every fattened pixel is gone (or replaced by the LiDAR's true depth).
  for (const auto& [row, col] : outliers) {
    if (refined.depth(row, col) > 0) {
      EXPECT_LT(std::abs(refined.depth(row, col) - truth(row, col)), 0.003f) << row << "," << col;
    }
    EXPECT_NE(refined.source[size_t(row) * intrinsics.width + col], DepthSource::kStereo);
  }
  for (int row = 110; row < 140; ++row) {
    for (int col = edge_col; col < edge_col + 4; ++col) {
      EXPECT_NE(refined.depth(row, col), 2.0f) << row << "," << col;
    }
  }
  // (Outliers may fall on the fattened block: at least the outliers plus the block minus overlaps.)
  EXPECT_GE(refined.stats.stereo_removed, outliers.size() + 4 * 30 - 5);

  // Fold 2: every filled depth lies on the surface the pixel sees: no depth between the plate and the
  // wall, and none of the wall where the plate is, however close to the edge (0.4 m off).
  size_t filled = 0, filled_in_plate_hole = 0, filled_in_band = 0;
  double max_fill_error = 0;
  for (int row = 0; row < intrinsics.height; ++row) {
    for (int col = 0; col < intrinsics.width; ++col) {
      if (refined.source[size_t(row) * intrinsics.width + col] != DepthSource::kLidar) {
        continue;
      }
      ++filled;
      max_fill_error =
          std::max(max_fill_error, double(std::abs(refined.depth(row, col) - truth(row, col))));
      filled_in_plate_hole += row >= 20 && row < 50 && col >= 30 && col < 70;
      filled_in_band += row >= 60 && row < 100 && col >= 100 && col < 140;
    }
  }
  std::cout << "filled " << filled << " pixels, max error " << max_fill_error * 1000
            << " mm; plate hole " << filled_in_plate_hole << "/1200, edge band " << filled_in_band
            << "/1600" << std::endl;
  EXPECT_LT(max_fill_error,
            0.003);  // 1 mm LiDAR noise, interpolated on the local plane
  EXPECT_GE(filled_in_plate_hole, 1200u * 95 / 100);
  // The band is filled on both sides of the edge, each side with its own surface (the bound above).
  EXPECT_GE(filled_in_band, 1600u * 3 / 4);
  // Normals of confirmed and filled pixels face the camera.
  const Eigen::Vector3f& normal = refined.normals.At(35, 50);
  EXPECT_LT(normal.dot(intrinsics.PixelRay(50, 35).cast<float>()), 0);
  EXPECT_NEAR(normal.norm(), 1, 1e-4);
}

// Each fill criterion on its own: with the others permissive, it alone refuses the fill.
TEST(LidarDepthRefinement, DoesNotFillGrazingOrCurvedSurfaces) {
  const PinholeIntrinsics intrinsics = Camera();
  LidarSurfaceOptions surface_options;
  surface_options.sample_spacing_m = 0.006;
  surface_options.radius_m = 0.03;
  surface_options.curvature_radius_m = 0.06;
  const DepthImage empty = DepthImage::Zero(intrinsics.height, intrinsics.width);

  // A plane tilted 70 degrees about the camera's y axis: seen at 55-85 degrees from its normal.
  std::vector<Eigen::Vector3d> tilted;
  const double slope = std::tan(70 * M_PI / 180);
  for (double y = -0.9; y <= 0.9; y += 0.003) {
    for (double x = -1.0; x <= 0.5; x += 0.003) {
      tilted.emplace_back(x, y, 2.5 + slope * x);
    }
  }
  const LidarSurface plane = BuildLidarSurface(tilted, surface_options);
  LidarDepthRefinementOptions angle_only;
  angle_only.max_fill_curvature = 1;
  const RefinedDepth by_angle = RefineDepthWithLidar(empty, plane, intrinsics, angle_only);
  angle_only.max_fill_view_angle_deg = 89;
  const RefinedDepth permissive = RefineDepthWithLidar(empty, plane, intrinsics, angle_only);
  const Eigen::Vector3d normal = Eigen::Vector3d(-slope, 0, 1).normalized();  // faces the camera
  size_t steep_filled = 0;
  for (int row = 0; row < intrinsics.height; ++row) {
    for (int col = 0; col < intrinsics.width; ++col) {
      const double angle =
          std::acos(std::abs(normal.dot(intrinsics.PixelRay(col, row).normalized()))) * 180 / M_PI;
      const size_t pixel = size_t(row) * intrinsics.width + col;
      if (by_angle.source[pixel] == DepthSource::kLidar) {
        EXPECT_LE(angle, 75.5) << row << "," << col;
      }
      steep_filled += angle > 77 && permissive.source[pixel] == DepthSource::kLidar;
    }
  }
  EXPECT_GT(by_angle.stats.filled, 100u);
  EXPECT_GT(steep_filled, 100u);

  // A ball of radius 2.5 cm: its curvature at the 3 cm scale refuses the fill.
  std::vector<Eigen::Vector3d> ball;
  for (double theta = 0; theta < M_PI / 2; theta += 0.01) {
    for (double phi = 0; phi < 2 * M_PI; phi += 0.01) {
      ball.emplace_back(0.025 * std::sin(theta) * std::cos(phi),
                        0.025 * std::sin(theta) * std::sin(phi),
                        2 - 0.025 * std::cos(theta));
    }
  }
  const LidarSurface sphere = BuildLidarSurface(ball, surface_options);
  LidarDepthRefinementOptions curvature_only;
  curvature_only.plane_tolerance_m = 0.1;
  curvature_only.max_normal_angle_deg = 89;
  curvature_only.max_fill_view_angle_deg = 89;
  EXPECT_EQ(RefineDepthWithLidar(empty, sphere, intrinsics, curvature_only).stats.filled, 0u);
  curvature_only.max_fill_curvature = 1;
  EXPECT_GT(RefineDepthWithLidar(empty, sphere, intrinsics, curvature_only).stats.filled, 10u);
}

TEST(LidarDepthRefinement, RejectsAMapOfTheWrongSize) {
  EXPECT_THROW(RefineDepthWithLidar(DepthImage::Zero(10, 10), {}, Camera(), {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
