// Depth images in an undistorted pinhole camera, Eigen only: what the densifier's depth-map operations
// (lidar_depth_refinement.h) work on.
//
// Pixel convention (COLMAP's): pixel (row, col) covers [col, col+1) x [row, row+1); its centre is at image
// coordinates (col + 0.5, row + 0.5), and x = fx * X / Z + cx.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace colmap_lidar {

// z-depth [m] per pixel, indexed (row, col); 0 = no depth.
using DepthImage = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct PinholeIntrinsics {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;

  bool Check() const;

  // Continuous image coordinates of a point in the camera frame; false behind the camera.
  bool Project(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* xy) const {
    if (point_in_cam.z() <= 0) return false;
    xy->x() = fx * point_in_cam.x() / point_in_cam.z() + cx;
    xy->y() = fy * point_in_cam.y() / point_in_cam.z() + cy;
    return true;
  }
  // The ray through a pixel's centre, scaled to z = 1.
  Eigen::Vector3d PixelRay(int col, int row) const {
    return Eigen::Vector3d((col + 0.5 - cx) / fx, (row + 0.5 - cy) / fy, 1);
  }
  bool Contains(const Eigen::Vector2d& xy) const {
    return xy.x() >= 0 && xy.y() >= 0 && xy.x() < width && xy.y() < height;
  }
};

// Per-pixel unit normals in the camera frame, facing the camera (n . ray < 0); zero = none.
struct NormalImage {
  int width = 0;
  int height = 0;
  std::vector<Eigen::Vector3f> normals;  // row-major

  NormalImage() = default;
  NormalImage(int w, int h)
      : width(w), height(h), normals(size_t(w) * h, Eigen::Vector3f::Zero()) {}
  Eigen::Vector3f& At(int row, int col) { return normals[size_t(row) * width + col]; }
  const Eigen::Vector3f& At(int row, int col) const { return normals[size_t(row) * width + col]; }
};

// Normals of a depth image from its back-projected neighbours (central differences over `step` pixels,
// one-sided where a neighbour is missing), facing the camera. Pixels without depth, or whose neighbours
// differ in depth by more than `max_relative_jump` (a depth edge), get no normal.
NormalImage NormalsFromDepth(const DepthImage& depth,
                             const PinholeIntrinsics& intrinsics,
                             int step = 2,
                             double max_relative_jump = 0.02);

}  // namespace colmap_lidar
