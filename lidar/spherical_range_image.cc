#include "lidar/spherical_range_image.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {
namespace {

double Elevation(const Eigen::Vector3d& p) { return std::atan2(p.z(), p.head<2>().norm()); }

bool Usable(const Eigen::Vector3d& p, double min_range) {
  return p.allFinite() && p.norm() >= min_range;
}

}  // namespace

double SphericalRangeImage::AutomaticResolution(
    const std::vector<Eigen::Vector3d>& points_in_sensor, double min_range) {
  double low = M_PI / 2, high = -M_PI / 2;
  size_t count = 0;
  for (const Eigen::Vector3d& p : points_in_sensor) {
    if (!Usable(p, min_range)) continue;
    const double elevation = Elevation(p);
    low = std::min(low, elevation), high = std::max(high, elevation);
    ++count;
  }
  if (count == 0) return M_PI / 180;
  const double solid_angle = 2 * M_PI * (std::sin(high) - std::sin(low));
  return 1.5 * std::sqrt(std::max(solid_angle, 1e-9) / double(count));
}

SphericalRangeImage::SphericalRangeImage(const std::vector<Eigen::Vector3d>& points_in_sensor,
                                         double resolution_rad,
                                         double min_range)
    : resolution_(resolution_rad) {
  if (!(resolution_rad > 0)) {
    throw std::invalid_argument("SphericalRangeImage: the resolution must be positive");
  }
  num_cols_ = static_cast<int>(std::ceil(2 * M_PI / resolution_));
  std::vector<std::pair<int, int>> cells(points_in_sensor.size(), {0, -1});
  int low = 0, high = -1;
  for (size_t i = 0; i < points_in_sensor.size(); ++i) {
    if (!Usable(points_in_sensor[i], min_range)) continue;
    CellOf(points_in_sensor[i], &cells[i].first, &cells[i].second);
    if (high < low) low = high = cells[i].first;
    low = std::min(low, cells[i].first), high = std::max(high, cells[i].first);
  }
  first_row_ = low;
  num_rows_ = high - low + 1;
  range_.assign(size_t(num_rows_) * num_cols_, 0.0);
  index_.assign(range_.size(), -1);
  for (size_t i = 0; i < points_in_sensor.size(); ++i) {
    if (cells[i].second < 0) continue;
    const size_t cell = size_t(cells[i].first - first_row_) * num_cols_ + cells[i].second;
    const double range = points_in_sensor[i].norm();
    if (index_[cell] < 0 || range < range_[cell]) range_[cell] = range, index_[cell] = int64_t(i);
  }
}

void SphericalRangeImage::CellOf(const Eigen::Vector3d& point_in_sensor, int* row, int* col) const {
  *row = static_cast<int>(std::floor((Elevation(point_in_sensor) + M_PI / 2) / resolution_));
  *col = std::clamp(
      static_cast<int>(
          std::floor((std::atan2(point_in_sensor.y(), point_in_sensor.x()) + M_PI) / resolution_)),
      0,
      num_cols_ - 1);
}

int64_t SphericalRangeImage::Index(int row, int col) const {
  if (row < first_row_ || row >= first_row_ + num_rows_ || col < 0 || col >= num_cols_) return -1;
  return index_[size_t(row - first_row_) * num_cols_ + col];
}

double SphericalRangeImage::Range(int row, int col) const {
  if (row < first_row_ || row >= first_row_ + num_rows_ || col < 0 || col >= num_cols_) return 0;
  return range_[size_t(row - first_row_) * num_cols_ + col];
}

double SphericalRangeImage::MinRangeAround(int row, int col, int radius) const {
  double nearest = 0;
  for (int r = row - radius; r <= row + radius; ++r) {
    for (int c = col - radius; c <= col + radius; ++c) {
      const double range = Range(r, ((c % num_cols_) + num_cols_) % num_cols_);
      if (range > 0 && (nearest == 0 || range < nearest)) nearest = range;
    }
  }
  return nearest;
}

}  // namespace colmap_lidar
