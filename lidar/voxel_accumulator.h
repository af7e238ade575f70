// Streaming voxel merge: points from many stations are added one station at a time and merged into one
// point per occupied voxel (mean position, mean colour, re-normalised mean normal). Memory grows with
// the number of occupied voxels (the surface area), not with the number of points added: added points
// wait in a buffer of at most a quarter of the voxels (at least 4 M points by default), which is then sorted and
// merged into the voxels, kept sorted by key. No per-voxel allocation (a hash map of 33 M voxels
// took 4 GB and a third of the densifier's time), and Extract's order is the keys' (deterministic).
// The voxels live in chunks of 2^20: growing never copies them (a vector's doubling held three
// times the voxels at once), and ExtractAndClear frees each chunk once its points are out.
#pragma once

#include "lidar/point_cloud.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace colmap_lidar {

// The key of the voxel (cube of side `voxel_size`, aligned with the origin) holding `point`: 21 bits
// per axis, +-1 million voxels around the origin (1 km at 1 mm); keys wrap beyond.
uint64_t VoxelKey(const Eigen::Vector3d& point, double voxel_size);

// The key of the voxel `offset` voxels away from the one of `key` (the inverse of VoxelKey's packing).
uint64_t NeighbourVoxelKey(uint64_t key, const Eigen::Vector3i& offset);

class VoxelAccumulator {
 public:
  // Throws std::invalid_argument for a voxel size <= 0. `min_buffered_points`: the buffer's size
  // before the first merge.
  explicit VoxelAccumulator(double voxel_size, size_t min_buffered_points = size_t(4) << 20);

  // `normal` may be zero (no normal); `color` is ignored when the accumulator has none.
  void Add(const Eigen::Vector3d& point, const Eigen::Vector3f& normal, const Color3ub& color);

  size_t NumVoxels() const;
  size_t NumPointsAdded() const { return num_added_; }

  // One point per voxel, with normals and colours; points with at least `min_points` contributions.
  PointCloud Extract(int min_points = 1) const;

  // Extract, then Clear, freeing the voxels chunk by chunk as the cloud fills: the voxels and their
  // cloud hardly coexist (B's 51 M voxels of 1 mm take 3.3 GB, their cloud 2.6 GB).
  PointCloud ExtractAndClear(int min_points = 1);
  // Frees the voxels.
  void Clear();

 private:
  struct Voxel {
    uint64_t key = 0;
    Eigen::Vector3d sum_point = Eigen::Vector3d::Zero();
    Eigen::Vector3f sum_normal = Eigen::Vector3f::Zero();
    Eigen::Vector3f sum_color = Eigen::Vector3f::Zero();
    uint32_t count = 0;
  };
  static constexpr int kChunkBits = 20;
  static constexpr size_t kChunkMask = (size_t(1) << kChunkBits) - 1;
  // Merges the buffer into the voxels (const: it changes the representation, not the content).
  void Compact() const;
  Voxel& At(size_t i) const { return chunks_[i >> kChunkBits][i & kChunkMask]; }
  // Grows to n voxels (new ones default), adding chunks; existing voxels stay where they are.
  void Resize(size_t n) const;
  // Appends voxel i's point, normal and colour to `cloud` if it has at least `min_points`.
  void AppendPoint(size_t i, int min_points, PointCloud* cloud) const;

  double voxel_size_;
  size_t min_buffered_points_;
  // Sorted by key, one per key: voxel i is At(i), i < num_voxels_.
  mutable std::vector<std::vector<Voxel>> chunks_;
  mutable size_t num_voxels_ = 0;
  // One per added point, in the order added.
  mutable std::vector<Voxel> pending_;
  size_t num_added_ = 0;
};

}  // namespace colmap_lidar
