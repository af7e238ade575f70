// Cost of the densifier's per-station work at the sizes of real captures: building the LiDAR surface
// (thinning, shifted-neighbourhood PCA, curvature) and refining a stereo depth map with it (splatting,
// fold 1, fold 2), for 1028x752 to 4112x3008 images and 0.1 to 1.6 M LiDAR points in view. The scene is
// synthetic (camera frame): a wall 3 m away and a 0.8 x 0.6 m box face 2.4 m away, seen by a LiDAR
// 0.15 m to the side with 1 cm range noise; the stereo map is the truth with 5 % holes and 2 % of
// pixels 2 cm off. Prints a Markdown table (time, and the accuracy of what was kept and filled).
//   densifier_benchmark
#include "lidar/lidar_depth_refinement.h"
#include "lidar/lidar_surface.h"

#include <omp.h>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <random>

namespace colmap_lidar {
namespace {

constexpr double kWallZ = 3.0, kBoxZ = 2.4, kBoxHalfX = 0.4, kBoxHalfY = 0.3;

double Seconds(const std::chrono::steady_clock::time_point& start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double TrueDepth(const Eigen::Vector3d& ray) {  // ray with z = 1
  const Eigen::Vector3d on_box = ray * kBoxZ;
  return std::abs(on_box.x()) < kBoxHalfX && std::abs(on_box.y()) < kBoxHalfY ? kBoxZ : kWallZ;
}

// Points the LiDAR sees, uniformly over the camera's view of the wall and the box face.
std::vector<Eigen::Vector3d> LidarPoints(const PinholeIntrinsics& camera,
                                         size_t count,
                                         std::mt19937* rng) {
  const Eigen::Vector3d lidar(0.15, 0, 0);
  std::normal_distribution<double> noise(0, 0.01);
  std::uniform_real_distribution<double> unit(0, 1);
  const double half_x = kWallZ * camera.cx / camera.fx;
  const double half_y = kWallZ * camera.cy / camera.fy;
  const double box_area = 4 * kBoxHalfX * kBoxHalfY;
  const double wall_area = 4 * half_x * half_y;
  std::vector<Eigen::Vector3d> points;
  points.reserve(count);
  while (points.size() < count) {
    Eigen::Vector3d point;
    if (unit(*rng) < box_area / (box_area + wall_area)) {
      point = Eigen::Vector3d(
          (2 * unit(*rng) - 1) * kBoxHalfX, (2 * unit(*rng) - 1) * kBoxHalfY, kBoxZ);
    } else {
      point = Eigen::Vector3d((2 * unit(*rng) - 1) * half_x, (2 * unit(*rng) - 1) * half_y, kWallZ);
      const Eigen::Vector3d at_box =
          lidar + (point - lidar) * ((kBoxZ - lidar.z()) / (point.z() - lidar.z()));
      if (std::abs(at_box.x()) < kBoxHalfX && std::abs(at_box.y()) < kBoxHalfY) {
        continue;  // in the box's shadow
      }
    }
    const Eigen::Vector3d direction = (point - lidar).normalized();
    points.push_back(point + direction * noise(*rng));
  }
  return points;
}

void Run() {
  std::cout << "| image | LiDAR points in view | surface samples | build surface | "
               "refine map | "
               "window | kept stereo error (mean) | filled | filled error (mean) |\n"
               "|---|---|---|---|---|---|---|---|---|\n";
  const std::vector<std::pair<double, size_t>> cases = {
      {1, 100000}, {1, 400000}, {2, 400000}, {4, 400000}, {4, 1600000}};
  for (const auto& [scale, num_points] : cases) {
    PinholeIntrinsics camera;
    camera.width = static_cast<int>(1028 * scale);
    camera.height = static_cast<int>(752 * scale);
    camera.fx = camera.fy = 1154 * scale;
    camera.cx = camera.width / 2.0;
    camera.cy = camera.height / 2.0;
    std::mt19937 rng(7);
    const std::vector<Eigen::Vector3d> points = LidarPoints(camera, num_points, &rng);
    DepthImage truth(camera.height, camera.width);
    DepthImage stereo(camera.height, camera.width);
    std::uniform_real_distribution<double> unit(0, 1);
    for (int row = 0; row < camera.height; ++row) {
      for (int col = 0; col < camera.width; ++col) {
        truth(row, col) = float(TrueDepth(camera.PixelRay(col, row)));
        const double u = unit(rng);
        stereo(row, col) = u < 0.05 ? 0.f : u < 0.07 ? truth(row, col) + 0.02f : truth(row, col);
      }
    }
    auto start = std::chrono::steady_clock::now();
    const LidarSurface surface = BuildLidarSurface(points, LidarSurfaceOptions());
    const double build_seconds = Seconds(start);
    start = std::chrono::steady_clock::now();
    const RefinedDepth refined =
        RefineDepthWithLidar(stereo, surface, camera, LidarDepthRefinementOptions());
    const double refine_seconds = Seconds(start);
    double kept_error = 0, filled_error = 0;
    size_t kept = 0, filled = 0;
    for (int row = 0; row < camera.height; ++row) {
      for (int col = 0; col < camera.width; ++col) {
        const DepthSource source = refined.source[size_t(row) * camera.width + col];
        const double error = std::abs(refined.depth(row, col) - truth(row, col));
        if (source == DepthSource::kStereo) kept_error += error, ++kept;
        if (source == DepthSource::kLidar) filled_error += error, ++filled;
      }
    }
    std::cout << std::fixed << "| " << camera.width << "x" << camera.height << " | " << num_points
              << " | " << surface.Size() << " | " << std::setprecision(2) << build_seconds
              << " s | " << refine_seconds << " s | " << refined.stats.window_radius_px << " px | "
              << kept_error / std::max<size_t>(1, kept) * 1000 << " mm | " << filled << " | "
              << filled_error / std::max<size_t>(1, filled) * 1000 << " mm |" << std::endl;
  }
  std::cout << "\n" << omp_get_max_threads() << " threads." << std::endl;
}

}  // namespace
}  // namespace colmap_lidar

int main() {
  colmap_lidar::Run();
  return 0;
}
