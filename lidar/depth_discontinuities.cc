#include "lidar/depth_discontinuities.h"

#include "lidar/spherical_range_image.h"
#include "lidar/util/check_option.h"

#include <algorithm>
#include <cmath>

namespace colmap_lidar {
namespace {

struct Cell {
  int row = 0;
  int col = 0;
  double range = 0;
  size_t index = 0;
};

// The occupied cells of the range image, sorted by row, then column.
std::vector<Cell> OccupiedCells(const SphericalRangeImage& image) {
  std::vector<Cell> cells;
  for (int row = image.FirstRow(); row < image.FirstRow() + image.NumRows(); ++row) {
    for (int col = 0; col < image.NumCols(); ++col) {
      const int64_t index = image.Index(row, col);
      if (index >= 0) cells.push_back(Cell{row, col, image.Range(row, col), size_t(index)});
    }
  }
  return cells;
}

// The ranges of up to context_cells occupied cells next to cell k in its row, nearest first, in
// direction -1 or +1 (each within max_gap_cells of the one before).
void RowRanges(const std::vector<Cell>& cells,
               size_t k,
               int direction,
               const DepthDiscontinuityOptions& options,
               std::vector<double>* ranges) {
  ranges->clear();
  size_t previous = k;
  for (int64_t j = int64_t(k) + direction;
       j >= 0 && j < int64_t(cells.size()) && int(ranges->size()) < options.context_cells;
       j += direction) {
    if (cells[j].row != cells[k].row ||
        std::abs(cells[j].col - cells[previous].col) > options.max_gap_cells) {
      break;
    }
    ranges->push_back(cells[j].range);
    previous = size_t(j);
  }
}

}  // namespace

bool DepthDiscontinuityOptions::Check() const {
  LIDAR_CHECK_OPTION_GE(angular_resolution_deg, 0);
  LIDAR_CHECK_OPTION_GT(gamma, 0);
  LIDAR_CHECK_OPTION_GE(min_score, 0);
  LIDAR_CHECK_OPTION_GT(max_slope_ratio, 0);
  LIDAR_CHECK_OPTION_GE(max_gap_cells, 1);
  LIDAR_CHECK_OPTION_GE(context_cells, 1);
  LIDAR_CHECK_OPTION_GE(min_range_m, 0);
  return true;
}

std::vector<DepthDiscontinuity> DetectDepthDiscontinuities(
    const std::vector<Eigen::Vector3d>& points_in_lidar, const DepthDiscontinuityOptions& options) {
  ThrowUnlessValid(options, "DepthDiscontinuityOptions");
  const double resolution =
      options.angular_resolution_deg > 0
          ? options.angular_resolution_deg * M_PI / 180
          : SphericalRangeImage::AutomaticResolution(points_in_lidar, options.min_range_m);
  const std::vector<Cell> cells =
      OccupiedCells(SphericalRangeImage(points_in_lidar, resolution, options.min_range_m));
  std::vector<DepthDiscontinuity> result;
  std::vector<double> before, after;
  for (size_t k = 0; k < cells.size(); ++k) {
    RowRanges(cells, k, -1, options, &before);
    RowRanges(cells, k, +1, options, &after);
    // Levinson & Thrun's X_i from the adjacent cells.
    const double to_before = before.empty() ? 0.0 : before[0] - cells[k].range;
    const double to_after = after.empty() ? 0.0 : after[0] - cells[k].range;
    const double step = std::max({to_before, to_after, 0.0});
    const double score = std::pow(step, options.gamma);
    if (!(step > 0 && score >= options.min_score)) continue;
    // An edge, not a grazing surface: the near side continues the point's surface and the far side
    // stays far, over context_cells cells each.
    const std::vector<double>& far = to_before >= to_after ? before : after;
    const std::vector<double>& near = to_before >= to_after ? after : before;
    if (near.empty()) continue;
    bool edge = true;
    for (double range : near)
      edge &= std::abs(range - cells[k].range) <= options.max_slope_ratio * step;
    for (double range : far) edge &= range - cells[k].range >= 0.5 * step;
    if (edge) result.push_back({points_in_lidar[cells[k].index], score});
  }
  std::stable_sort(
      result.begin(), result.end(), [](const auto& a, const auto& b) { return a.score > b.score; });
  if (options.max_points > 0 && result.size() > options.max_points) {
    result.resize(options.max_points);
  }
  return result;
}

}  // namespace colmap_lidar
