// Synthetic clouds for unit tests: points sampled uniformly on axis-aligned boxes' faces (a room with
// objects), with outward normals. Header-only, Eigen and the lidar point cloud type only.
#pragma once

#include "lidar/point_cloud.h"

#include <random>

namespace colmap_lidar {
namespace testing {

// Samples `density` points per m^2 on the 6 faces of the box [lo, hi]; normals point outwards
// (`inward` = true for the inside of a room).
inline void SampleBox(const Eigen::Vector3d& lo,
                      const Eigen::Vector3d& hi,
                      double density,
                      bool inward,
                      std::mt19937* rng,
                      PointCloud* cloud) {
  std::uniform_real_distribution<double> unit(0, 1);
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const double area = (hi[u] - lo[u]) * (hi[v] - lo[v]);
    const int n = static_cast<int>(area * density);
    for (const int side : {0, 1}) {
      Eigen::Vector3d normal = Eigen::Vector3d::Zero();
      normal[axis] = (side ? 1.0 : -1.0) * (inward ? -1.0 : 1.0);
      for (int k = 0; k < n; ++k) {
        Eigen::Vector3d p;
        p[axis] = side ? hi[axis] : lo[axis];
        p[u] = lo[u] + unit(*rng) * (hi[u] - lo[u]);
        p[v] = lo[v] + unit(*rng) * (hi[v] - lo[v]);
        cloud->points.push_back(p);
        cloud->normals.push_back(normal);
      }
    }
  }
}

// A 12 x 9 x 4 m room with three boxes in it: enough structure to constrain all six DoF of ICP.
inline PointCloud SyntheticRoom(double density, uint32_t seed, double noise = 0) {
  std::mt19937 rng(seed);
  PointCloud cloud;
  SampleBox({-6, -4.5, 0}, {6, 4.5, 4}, density, true, &rng, &cloud);
  SampleBox({1, 1, 0}, {2.5, 2, 1.2}, density, false, &rng, &cloud);
  SampleBox({-3, -2.5, 0}, {-2.2, -1, 2.0}, density, false, &rng, &cloud);
  SampleBox({-1, 2.5, 0}, {0.5, 3.5, 0.8}, density, false, &rng, &cloud);
  if (noise > 0) {
    std::normal_distribution<double> gaussian(0, noise);
    for (size_t i = 0; i < cloud.Size(); ++i) cloud.points[i] += gaussian(rng) * cloud.normals[i];
  }
  return cloud;
}

}  // namespace testing
}  // namespace colmap_lidar
