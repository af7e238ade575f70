#include "lidar/lidar_surface.h"

#include "lidar/kd_tree.h"
#include "lidar/preprocessing.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {

bool LidarSurfaceOptions::Check() const {
  if (!(sample_spacing_m > 0) || !(radius_m > sample_spacing_m)) {
    throw std::invalid_argument(
        "LidarSurfaceOptions: need 0 < sample_spacing_m < radius_m");
  }
  if (min_neighbors < 3 || max_neighbors < min_neighbors) {
    throw std::invalid_argument(
        "LidarSurfaceOptions: need 3 <= min_neighbors <= max_neighbors");
  }
  return true;
}

LidarSurface BuildLidarSurface(const std::vector<Eigen::Vector3d>& points_in_cam,
                               const LidarSurfaceOptions& options) {
  options.Check();
  LidarSurface surface;
  if (points_in_cam.empty()) return surface;
  PointCloud raw;
  raw.points = points_in_cam;
  const PointCloud thinned = VoxelDownsample(raw, options.sample_spacing_m);
  const std::vector<Eigen::Vector3d>& samples = thinned.points;
  const KdTree3 tree(samples);

  std::vector<Eigen::Vector3d> points(samples.size());
  std::vector<Eigen::Vector3d> normals(samples.size());
  std::vector<float> curvature(samples.size(), -1.f);  // -1: dropped
  std::vector<float> spacing(samples.size(), 0.f);
#pragma omp parallel
  {
    std::vector<size_t> indices;
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < samples.size(); ++i) {
      tree.RadiusSearch(samples[i], options.radius_m, &indices);
      if (static_cast<int>(indices.size()) < options.min_neighbors) continue;
      const size_t stride =
          (indices.size() + options.max_neighbors - 1) / options.max_neighbors;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      size_t count = 0;
      for (size_t k = 0; k < indices.size(); k += stride, ++count) {
        mean += samples[indices[k]];
      }
      mean /= double(count);
      Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
      for (size_t k = 0; k < indices.size(); k += stride) {
        const Eigen::Vector3d d = samples[indices[k]] - mean;
        covariance += d * d.transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
      Eigen::Vector3d normal = solver.eigenvectors().col(0);
      if (normal.dot(samples[i]) > 0) normal = -normal;  // face the camera
      const double sum = solver.eigenvalues().sum();
      points[i] = samples[i] - normal * normal.dot(samples[i] - mean);
      normals[i] = normal;
      spacing[i] = float(options.radius_m * std::sqrt(M_PI / indices.size()));
      curvature[i] = float(
          sum > 0 ? std::max(0.0, solver.eigenvalues()(0)) / sum : 0.0);
    }
  }
  for (size_t i = 0; i < samples.size(); ++i) {
    if (curvature[i] < 0) continue;
    surface.points.push_back(points[i]);
    surface.normals.push_back(normals[i]);
    surface.curvature.push_back(curvature[i]);
    surface.spacing.push_back(spacing[i]);
  }
  return surface;
}

}  // namespace colmap_lidar
