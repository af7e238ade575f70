#include "lidar/voxel_hash_map.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_set>

namespace colmap_lidar {
namespace {

Eigen::Vector3i Voxel(const Eigen::Vector3d& point, double voxel_size) {
  return (point / voxel_size).array().floor().cast<int>();
}

struct Hash {
  size_t operator()(const Eigen::Vector3i& voxel) const {
    // Three large primes (Teschner et al. 2003, spatial hashing).
    return static_cast<size_t>(voxel.x()) * 73856093u ^ static_cast<size_t>(voxel.y()) * 19349669u ^
           static_cast<size_t>(voxel.z()) * 83492791u;
  }
};

}  // namespace

size_t VoxelHashMap::VoxelHash::operator()(const Eigen::Vector3i& voxel) const {
  return Hash()(voxel);
}

VoxelHashMap::VoxelHashMap(double voxel_size, double max_distance, int max_points_per_voxel)
    : voxel_size_(voxel_size),
      max_distance_(max_distance),
      max_points_per_voxel_(static_cast<size_t>(std::max(max_points_per_voxel, 0))) {
  if (!(voxel_size > 0) || !(max_distance > 0) || max_points_per_voxel < 1) {
    throw std::invalid_argument(
        "VoxelHashMap: voxel size, distance and points per voxel must be > 0");
  }
}

Eigen::Vector3i VoxelHashMap::VoxelOf(const Eigen::Vector3d& point) const {
  return Voxel(point, voxel_size_);
}

void VoxelHashMap::Update(const std::vector<Eigen::Vector3d>& points_in_world,
                          const Eigen::Vector3d& origin) {
  for (const Eigen::Vector3d& point : points_in_world) {
    std::vector<Eigen::Vector3d>& voxel = voxels_[VoxelOf(point)];
    if (voxel.size() < max_points_per_voxel_) voxel.push_back(point);
  }
  const double max_squared = max_distance_ * max_distance_;
  for (auto it = voxels_.begin(); it != voxels_.end();) {
    if ((it->second.front() - origin).squaredNorm() > max_squared) {
      it = voxels_.erase(it);
    } else {
      ++it;
    }
  }
}

bool VoxelHashMap::NearestNeighbor(const Eigen::Vector3d& query,
                                   Eigen::Vector3d* neighbor,
                                   double* distance) const {
  const Eigen::Vector3i centre = VoxelOf(query);
  double best = std::numeric_limits<double>::infinity();
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = voxels_.find(centre + Eigen::Vector3i(dx, dy, dz));
        if (it == voxels_.end()) continue;
        for (const Eigen::Vector3d& point : it->second) {
          const double squared = (point - query).squaredNorm();
          if (squared < best) {
            best = squared;
            *neighbor = point;
          }
        }
      }
    }
  }
  if (!std::isfinite(best)) return false;
  *distance = std::sqrt(best);
  return true;
}

std::vector<Eigen::Vector3d> VoxelHashMap::PointsNear(const Eigen::Vector3d& query,
                                                      double radius) const {
  const Eigen::Vector3i low = VoxelOf(query - Eigen::Vector3d::Constant(radius));
  const Eigen::Vector3i high = VoxelOf(query + Eigen::Vector3d::Constant(radius));
  std::vector<Eigen::Vector3d> near;
  for (int x = low.x(); x <= high.x(); ++x) {
    for (int y = low.y(); y <= high.y(); ++y) {
      for (int z = low.z(); z <= high.z(); ++z) {
        const auto it = voxels_.find(Eigen::Vector3i(x, y, z));
        if (it == voxels_.end()) continue;
        for (const Eigen::Vector3d& point : it->second) {
          if ((point - query).squaredNorm() <= radius * radius) near.push_back(point);
        }
      }
    }
  }
  return near;
}

std::vector<Eigen::Vector3d> VoxelHashMap::Points() const {
  std::vector<Eigen::Vector3d> points;
  for (const auto& [voxel, voxel_points] : voxels_) {
    points.insert(points.end(), voxel_points.begin(), voxel_points.end());
  }
  return points;
}

std::vector<Eigen::Vector3d> FirstPointPerVoxel(const std::vector<Eigen::Vector3d>& points,
                                                double voxel_size) {
  if (!(voxel_size > 0)) throw std::invalid_argument("FirstPointPerVoxel: voxel size must be > 0");
  std::unordered_set<Eigen::Vector3i, Hash> occupied;
  occupied.reserve(points.size());
  std::vector<Eigen::Vector3d> kept;
  for (const Eigen::Vector3d& point : points) {
    if (occupied.insert(Voxel(point, voxel_size)).second) kept.push_back(point);
  }
  return kept;
}

}  // namespace colmap_lidar
