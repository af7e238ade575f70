#include "lidar/point_cloud.h"

#include <stdexcept>
#include <string>

namespace colmap_lidar {
namespace {

void CheckAttribute(size_t num_points, size_t num_values, const char* name) {
  if (num_values != 0 && num_values != num_points) {
    throw std::invalid_argument(std::string("Point cloud has ") + std::to_string(num_points) +
                                " points but " + std::to_string(num_values) + " " + name);
  }
}

}  // namespace

void PointCloud::CheckConsistent() const {
  CheckAttribute(points.size(), normals.size(), "normals");
  CheckAttribute(points.size(), colors.size(), "colors");
  CheckAttribute(points.size(), intensities.size(), "intensities");
  CheckAttribute(points.size(), times.size(), "times");
}

void PointCloud::Reserve(size_t n, bool with_normals, bool with_colors, bool with_intensities) {
  points.reserve(n);
  if (with_normals) normals.reserve(n);
  if (with_colors) colors.reserve(n);
  if (with_intensities) intensities.reserve(n);
}

}  // namespace colmap_lidar
