#include "lidar/spherical_range_image.h"

#include <gtest/gtest.h>

#include <cmath>

namespace colmap_lidar {
namespace {

Eigen::Vector3d Direction(double azimuth_deg, double elevation_deg, double range) {
  const double a = azimuth_deg * M_PI / 180, e = elevation_deg * M_PI / 180;
  return range * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
}

TEST(SphericalRangeImage, KeepsTheNearestPointOfEachCell) {
  const std::vector<Eigen::Vector3d> points = {
      Direction(10.1, 0.1, 8), Direction(10.2, 0.2, 5), Direction(30, 0.1, 7)};
  const SphericalRangeImage image(points, M_PI / 180, 0.5);
  int row = 0, col = 0;
  image.CellOf(points[0], &row, &col);
  EXPECT_EQ(image.Index(row, col), 1);
  EXPECT_DOUBLE_EQ(image.Range(row, col), 5);
  image.CellOf(points[2], &row, &col);
  EXPECT_EQ(image.Index(row, col), 2);
  EXPECT_EQ(image.Index(row, col - 1), -1);
  EXPECT_EQ(image.Range(row + 100, col), 0);  // out of the image
}

TEST(SphericalRangeImage, LeavesOutNearAndNonFinitePoints) {
  const std::vector<Eigen::Vector3d> points = {
      Direction(0, 0, 0.2), Eigen::Vector3d(NAN, 0, 0), Direction(50, 0, 4)};
  const SphericalRangeImage image(points, M_PI / 180, 0.5);
  int row = 0, col = 0;
  image.CellOf(points[0], &row, &col);
  EXPECT_EQ(image.Index(row, col), -1);
  image.CellOf(points[2], &row, &col);
  EXPECT_EQ(image.Index(row, col), 2);
}

// The columns wrap at +-180 deg: a cell at the last column sees its neighbour at the first.
TEST(SphericalRangeImage, MinRangeAroundWrapsTheAzimuth) {
  const std::vector<Eigen::Vector3d> points = {Direction(179.7, 0.5, 9), Direction(-179.7, 0.5, 3)};
  const SphericalRangeImage image(points, M_PI / 180, 0.5);
  int row = 0, col = 0;
  image.CellOf(points[0], &row, &col);
  EXPECT_EQ(col, image.NumCols() - 1);
  EXPECT_DOUBLE_EQ(image.MinRangeAround(row, col, 0), 9);
  EXPECT_DOUBLE_EQ(image.MinRangeAround(row, col, 1), 3);
  EXPECT_DOUBLE_EQ(image.MinRangeAround(row + 5, col, 1), 0);  // nothing around
}

TEST(SphericalRangeImage, RefusesANonPositiveResolution) {
  EXPECT_THROW(SphericalRangeImage({Eigen::Vector3d(1, 0, 0)}, 0.0, 0.5), std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
