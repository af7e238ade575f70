#include "lidar/moving_points.h"

#include "lidar/spherical_range_image.h"
#include "lidar/util/check_option.h"
#include "lidar/util/parallel_for_each.h"

#include <memory>
#include <stdexcept>
#include <string>

namespace colmap_lidar {
namespace {

// Whether the cloud of `image` saw beyond the point (given in that cloud's frame): its nearest return
// around the point's direction is farther than the point by the margin.
bool SeesThrough(const SphericalRangeImage& image,
                 const Eigen::Vector3d& point_in_lidar,
                 const MovingPointOptions& options) {
  const double range = point_in_lidar.norm();
  if (!(range >= options.min_range_m)) return false;
  int row = 0, col = 0;
  image.CellOf(point_in_lidar, &row, &col);
  const double nearest = image.MinRangeAround(row, col, options.neighbourhood_cells);
  return nearest > 0 && nearest >= range + options.margin_m + options.margin_ratio * range;
}

// The clouds compared with cloud i: up to num_neighbour_clouds of its component on each side.
std::vector<int> NeighbourClouds(int i, const std::vector<int>& component, int max_per_side) {
  std::vector<int> neighbours;
  const int n = static_cast<int>(component.size());
  for (const int direction : {-1, 1}) {
    int found = 0;
    for (int j = i + direction; j >= 0 && j < n && found < max_per_side; j += direction) {
      if (component[j] != component[i]) continue;
      neighbours.push_back(j);
      ++found;
    }
  }
  return neighbours;
}

}  // namespace

bool MovingPointOptions::Check() const {
  LIDAR_CHECK_OPTION_GE(angular_resolution_deg, 0);
  LIDAR_CHECK_OPTION_GE(num_neighbour_clouds, 1);
  LIDAR_CHECK_OPTION_GT(margin_m, 0);
  LIDAR_CHECK_OPTION_GE(margin_ratio, 0);
  LIDAR_CHECK_OPTION_GE(neighbourhood_cells, 0);
  LIDAR_CHECK_OPTION_GE(min_votes, 1);
  LIDAR_CHECK_OPTION_GE(min_range_m, 0);
  return true;
}

std::vector<std::vector<uint8_t>> FlagMovingPoints(
    const std::vector<const std::vector<Eigen::Vector3d>*>& points_in_lidar,
    const std::vector<Eigen::Isometry3d>& world_from_lidar,
    const std::vector<int>& component,
    const MovingPointOptions& options) {
  ThrowUnlessValid(options, "MovingPointOptions");
  const int n = static_cast<int>(points_in_lidar.size());
  if (world_from_lidar.size() != size_t(n) ||
      (!component.empty() && component.size() != size_t(n))) {
    throw std::invalid_argument("FlagMovingPoints: " + std::to_string(n) + " clouds but " +
                                std::to_string(world_from_lidar.size()) + " poses and " +
                                std::to_string(component.size()) + " components");
  }
  const std::vector<int> components = component.empty() ? std::vector<int>(n, 0) : component;
  std::vector<std::unique_ptr<SphericalRangeImage>> images(n);
  ParallelForEach(n, [&](int i) {
    const double resolution =
        options.angular_resolution_deg > 0
            ? options.angular_resolution_deg * M_PI / 180
            : SphericalRangeImage::AutomaticResolution(*points_in_lidar[i], options.min_range_m);
    images[i] =
        std::make_unique<SphericalRangeImage>(*points_in_lidar[i], resolution, options.min_range_m);
  });
  std::vector<std::vector<uint8_t>> flags(n);
  ParallelForEach(n, [&](int i) {
    const std::vector<Eigen::Vector3d>& points = *points_in_lidar[i];
    std::vector<int> votes(points.size(), 0);
    for (const int j : NeighbourClouds(i, components, options.num_neighbour_clouds)) {
      const Eigen::Isometry3d j_from_i = world_from_lidar[j].inverse() * world_from_lidar[i];
      for (size_t k = 0; k < points.size(); ++k) {
        if (points[k].allFinite() && SeesThrough(*images[j], j_from_i * points[k], options)) {
          ++votes[k];
        }
      }
    }
    flags[i].resize(points.size());
    for (size_t k = 0; k < points.size(); ++k) flags[i][k] = votes[k] >= options.min_votes;
  });
  return flags;
}

}  // namespace colmap_lidar
