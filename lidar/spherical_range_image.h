// A spherical range image of a cloud about its sensor (the origin of the cloud's frame): rows of
// constant elevation, columns of azimuth (wrapping at +-180 deg), the nearest point of each cell. It
// stands in for a sensor's firing order, which clouds on disk rarely keep: with the angular
// resolution of one ring (e.g. 0.4 deg for an HDL-64) the rows are the rings.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace colmap_lidar {

class SphericalRangeImage {
 public:
  // `points_in_sensor` with the sensor at the origin; `resolution_rad` > 0 is the cell size in
  // elevation and azimuth. Points nearer than `min_range` and non-finite points are left out.
  SphericalRangeImage(const std::vector<Eigen::Vector3d>& points_in_sensor,
                      double resolution_rad,
                      double min_range);

  // The cell size at which the points, spread evenly over the elevations they cover, would fill
  // each cell once, times 1.5 (so that most cells are occupied) [rad].
  static double AutomaticResolution(const std::vector<Eigen::Vector3d>& points_in_sensor,
                                    double min_range);

  double Resolution() const { return resolution_; }
  int NumCols() const { return num_cols_; }
  // Rows run from FirstRow() to FirstRow() + NumRows() - 1, row r covering elevations
  // [r * resolution - 90 deg, (r + 1) * resolution - 90 deg).
  int FirstRow() const { return first_row_; }
  int NumRows() const { return num_rows_; }

  // The cell of a direction (any point but the origin); the row may lie outside the image.
  void CellOf(const Eigen::Vector3d& point_in_sensor, int* row, int* col) const;
  // Index into the input of the cell's nearest point, -1 when the cell is empty or out of the image.
  int64_t Index(int row, int col) const;
  // Range of the cell's nearest point; 0 when the cell is empty or out of the image.
  double Range(int row, int col) const;
  // The smallest range over the occupied cells within `radius` cells of (row, col) (columns wrap);
  // 0 when all of them are empty.
  double MinRangeAround(int row, int col, int radius) const;

 private:
  double resolution_ = 0;
  int num_cols_ = 0;
  int first_row_ = 0;
  int num_rows_ = 0;
  std::vector<double> range_;   // 0: empty
  std::vector<int64_t> index_;  // -1: empty
};

}  // namespace colmap_lidar
