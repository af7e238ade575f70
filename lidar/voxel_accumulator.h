// Streaming voxel merge: points from many stations are added one station at a time and merged into one
// point per occupied voxel (mean position, mean colour, re-normalised mean normal). Memory grows with
// the number of occupied voxels (the surface area), not with the number of points added.
#pragma once

#include "lidar/point_cloud.h"

#include <Eigen/Core>

#include <cstdint>
#include <unordered_map>

namespace colmap_lidar {

class VoxelAccumulator {
 public:
  explicit VoxelAccumulator(double voxel_size);  // throws std::invalid_argument for <= 0

  // `normal` may be zero (no normal); `color` is ignored when the accumulator has none.
  void Add(const Eigen::Vector3d& point, const Eigen::Vector3f& normal, const Color3ub& color);

  size_t NumVoxels() const { return voxels_.size(); }
  size_t NumPointsAdded() const { return num_added_; }

  // One point per voxel, with normals and colours; points with at least `min_points` contributions.
  PointCloud Extract(int min_points = 1) const;

 private:
  struct Voxel {
    Eigen::Vector3d sum_point = Eigen::Vector3d::Zero();
    Eigen::Vector3f sum_normal = Eigen::Vector3f::Zero();
    Eigen::Vector3f sum_color = Eigen::Vector3f::Zero();
    uint32_t count = 0;
  };
  uint64_t Key(const Eigen::Vector3d& point) const;

  double voxel_size_;
  std::unordered_map<uint64_t, Voxel> voxels_;
  size_t num_added_ = 0;
};

}  // namespace colmap_lidar
