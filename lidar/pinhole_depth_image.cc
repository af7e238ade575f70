#include "lidar/pinhole_depth_image.h"

#include "lidar/util/check_option.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace colmap_lidar {

bool PinholeIntrinsics::Check() const {
  LIDAR_CHECK_OPTION_GT(width, 0);
  LIDAR_CHECK_OPTION_GT(height, 0);
  LIDAR_CHECK_OPTION_GT(fx, 0);
  LIDAR_CHECK_OPTION_GT(fy, 0);
  LIDAR_CHECK_OPTION(std::isfinite(cx) && std::isfinite(cy));
  return true;
}

NormalImage NormalsFromDepth(const DepthImage& depth,
                             const PinholeIntrinsics& intrinsics,
                             int step,
                             double max_relative_jump) {
  const int height = static_cast<int>(depth.rows());
  const int width = static_cast<int>(depth.cols());
  NormalImage result(width, height);
  auto point = [&](int col, int row) -> Eigen::Vector3d {
    return intrinsics.PixelRay(col, row) * double(depth(row, col));
  };
  // The neighbour `offset` pixels away along one axis if it has depth close to `z`, else none.
  auto usable = [&](int col, int row, float z) {
    return col >= 0 && row >= 0 && col < width && row < height && depth(row, col) > 0 &&
           std::abs(depth(row, col) - z) <= max_relative_jump * z;
  };
#pragma omp parallel for schedule(dynamic, 16)
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const float z = depth(row, col);
      if (!(z > 0)) continue;
      Eigen::Vector3d tangents[2];
      bool ok = true;
      for (int axis = 0; axis < 2 && ok; ++axis) {
        const int dc = axis == 0 ? step : 0;
        const int dr = axis == 1 ? step : 0;
        const bool plus = usable(col + dc, row + dr, z);
        const bool minus = usable(col - dc, row - dr, z);
        if (plus && minus) {
          tangents[axis] = point(col + dc, row + dr) - point(col - dc, row - dr);
        } else if (plus) {
          tangents[axis] = point(col + dc, row + dr) - point(col, row);
        } else if (minus) {
          tangents[axis] = point(col, row) - point(col - dc, row - dr);
        } else {
          ok = false;
        }
      }
      if (!ok) continue;
      Eigen::Vector3d normal = tangents[0].cross(tangents[1]);
      if (normal.norm() < 1e-12) continue;
      normal.normalize();
      if (normal.dot(intrinsics.PixelRay(col, row)) > 0) normal = -normal;
      result.At(row, col) = normal.cast<float>();
    }
  }
  return result;
}

}  // namespace colmap_lidar
