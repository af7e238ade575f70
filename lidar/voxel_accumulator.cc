#include "lidar/voxel_accumulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {

VoxelAccumulator::VoxelAccumulator(double voxel_size, size_t min_buffered_points)
    : voxel_size_(voxel_size), min_buffered_points_(std::max<size_t>(1, min_buffered_points)) {
  if (!(voxel_size > 0)) {
    throw std::invalid_argument("VoxelAccumulator: voxel_size must be > 0");
  }
}

namespace {
constexpr int kBitsPerAxis = 21;
constexpr int64_t kAxisMask = (int64_t(1) << kBitsPerAxis) - 1;
}  // namespace

uint64_t VoxelKey(const Eigen::Vector3d& point, double voxel_size) {
  constexpr int64_t kOffset = int64_t(1) << (kBitsPerAxis - 1);
  uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int64_t cell = static_cast<int64_t>(std::floor(point[axis] / voxel_size)) + kOffset;
    key = (key << kBitsPerAxis) | static_cast<uint64_t>(cell & kAxisMask);
  }
  return key;
}

uint64_t NeighbourVoxelKey(uint64_t key, const Eigen::Vector3i& offset) {
  uint64_t neighbour = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int shift = kBitsPerAxis * (2 - axis);
    const int64_t cell = static_cast<int64_t>((key >> shift) & kAxisMask) + offset[axis];
    neighbour |= static_cast<uint64_t>(cell & kAxisMask) << shift;
  }
  return neighbour;
}

namespace {

template <typename VoxelT>
void Accumulate(const VoxelT& from, VoxelT* into) {
  into->sum_point += from.sum_point;
  into->sum_normal += from.sum_normal;
  into->sum_color += from.sum_color;
  into->count += from.count;
}

}  // namespace

void VoxelAccumulator::Add(const Eigen::Vector3d& point,
                           const Eigen::Vector3f& normal,
                           const Color3ub& color) {
  if (!point.allFinite()) return;
  pending_.push_back({VoxelKey(point, voxel_size_), point, normal, color.cast<float>(), 1});
  ++num_added_;
  if (pending_.size() >= std::max(min_buffered_points_, num_voxels_ / 4)) Compact();
}

void VoxelAccumulator::Compact() const {
  if (pending_.empty()) return;
  std::sort(pending_.begin(), pending_.end(), [](const Voxel& a, const Voxel& b) {
    return a.key < b.key;
  });
  // Runs of one key into one voxel each, in place; those whose key is already a voxel go there.
  size_t num_runs = 0;
  size_t v = 0;
  for (size_t p = 0; p < pending_.size();) {
    Voxel run = pending_[p++];
    while (p < pending_.size() && pending_[p].key == run.key) Accumulate(pending_[p++], &run);
    while (v < num_voxels_ && At(v).key < run.key) ++v;
    if (v < num_voxels_ && At(v).key == run.key) {
      Accumulate(run, &At(v));
    } else {
      pending_[num_runs++] = run;
    }
  }
  // The new voxels merged in from the back: no second copy of the voxels.
  size_t old_end = num_voxels_;
  Resize(old_end + num_runs);
  for (size_t out = num_voxels_; num_runs > 0;) {
    if (old_end > 0 && At(old_end - 1).key > pending_[num_runs - 1].key) {
      At(--out) = At(--old_end);
    } else {
      At(--out) = pending_[--num_runs];
    }
  }
  pending_.clear();
}

void VoxelAccumulator::Resize(size_t n) const {
  while ((chunks_.size() << kChunkBits) < n) chunks_.emplace_back(size_t(1) << kChunkBits);
  num_voxels_ = n;
}

size_t VoxelAccumulator::NumVoxels() const {
  Compact();
  return num_voxels_;
}

void VoxelAccumulator::AppendPoint(size_t i, int min_points, PointCloud* cloud) const {
  const Voxel& voxel = At(i);
  if (voxel.count < static_cast<uint32_t>(std::max(1, min_points))) return;
  cloud->points.push_back(voxel.sum_point / voxel.count);
  const Eigen::Vector3f normal = voxel.sum_normal;
  cloud->normals.push_back(normal.norm() > 0 ? Eigen::Vector3d(normal.normalized().cast<double>())
                                             : Eigen::Vector3d::Zero());
  const Eigen::Vector3f color = voxel.sum_color / float(voxel.count);
  cloud->colors.push_back((color.array() + 0.5f).min(255.f).cast<uint8_t>().matrix());
}

PointCloud VoxelAccumulator::Extract(int min_points) const {
  Compact();
  PointCloud cloud;
  cloud.Reserve(num_voxels_, true, true, false);
  for (size_t i = 0; i < num_voxels_; ++i) AppendPoint(i, min_points, &cloud);
  return cloud;
}

PointCloud VoxelAccumulator::ExtractAndClear(int min_points) {
  Compact();
  std::vector<Voxel>().swap(
      pending_);  // the merge buffer's capacity (up to a quarter of the voxels)
  PointCloud cloud;
  // Reserved, not touched: the pages become resident as the chunks are freed.
  cloud.Reserve(num_voxels_, true, true, false);
  for (size_t i = 0; i < num_voxels_; ++i) {
    AppendPoint(i, min_points, &cloud);
    if (((i + 1) & kChunkMask) == 0) std::vector<Voxel>().swap(chunks_[i >> kChunkBits]);
  }
  Clear();
  return cloud;
}

void VoxelAccumulator::Clear() {
  std::vector<std::vector<Voxel>>().swap(chunks_);
  num_voxels_ = 0;
  std::vector<Voxel>().swap(pending_);
  num_added_ = 0;
}

}  // namespace colmap_lidar
