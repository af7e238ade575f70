#include "lidar/voxel_accumulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {

VoxelAccumulator::VoxelAccumulator(double voxel_size) : voxel_size_(voxel_size) {
  if (!(voxel_size > 0)) {
    throw std::invalid_argument("VoxelAccumulator: voxel_size must be > 0");
  }
}

uint64_t VoxelAccumulator::Key(const Eigen::Vector3d& point) const {
  // 21 bits per axis around the origin: +-1 million voxels, 1 km at 1 mm.
  constexpr int64_t kOffset = int64_t(1) << 20;
  constexpr int64_t kMask = (int64_t(1) << 21) - 1;
  uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int64_t cell = static_cast<int64_t>(std::floor(point[axis] / voxel_size_)) + kOffset;
    key = (key << 21) | static_cast<uint64_t>(cell & kMask);
  }
  return key;
}

void VoxelAccumulator::Add(const Eigen::Vector3d& point,
                           const Eigen::Vector3f& normal,
                           const Color3ub& color) {
  if (!point.allFinite()) return;
  Voxel& voxel = voxels_[Key(point)];
  voxel.sum_point += point;
  voxel.sum_normal += normal;
  voxel.sum_color += color.cast<float>();
  ++voxel.count;
  ++num_added_;
}

PointCloud VoxelAccumulator::Extract(int min_points) const {
  PointCloud cloud;
  cloud.Reserve(voxels_.size(), true, true, false);
  for (const auto& [key, voxel] : voxels_) {
    if (voxel.count < static_cast<uint32_t>(std::max(1, min_points))) continue;
    cloud.points.push_back(voxel.sum_point / voxel.count);
    const Eigen::Vector3f normal = voxel.sum_normal;
    cloud.normals.push_back(normal.norm() > 0 ? Eigen::Vector3d(normal.normalized().cast<double>())
                                              : Eigen::Vector3d::Zero());
    const Eigen::Vector3f color = voxel.sum_color / float(voxel.count);
    cloud.colors.push_back((color.array() + 0.5f).min(255.f).cast<uint8_t>().matrix());
  }
  return cloud;
}

}  // namespace colmap_lidar
