#include "lidar/voxel_hash_map.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_set>

namespace colmap_lidar {
namespace {

Eigen::Vector3i VoxelIndex(const Eigen::Vector3d& point, double voxel_size) {
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
  return VoxelIndex(point, voxel_size_);
}

namespace {

// First and second moments of points taken relative to `origin` (near them: no cancellation).
struct PointMoments {
  explicit PointMoments(const Eigen::Vector3d& origin) : origin(origin) {}
  void Add(const Eigen::Vector3d& point) {
    const Eigen::Vector3d p = point - origin;
    sum += p;
    outer += p * p.transpose();
    ++count;
  }
  Eigen::Vector3d origin;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  size_t count = 0;
};

// The shape of the points whose moments are given (PCA of their scatter).
void ClassifyShape(const PointMoments& moments, VoxelShape* shape, Eigen::Vector3d* normal) {
  *shape = VoxelShape::kSparse;
  if (moments.count < 5) return;
  *shape = VoxelShape::kScattered;
  const Eigen::Matrix3d scatter =
      moments.outer - moments.sum * moments.sum.transpose() / static_cast<double>(moments.count);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const Eigen::Vector3d& variances = solver.eigenvalues();
  // Spreads (square roots) below 0.2 of the largest: a line; else thin across (below 0.3 of the
  // middle spread): a plane.
  if (variances(1) < 0.04 * variances(2)) {
    *shape = VoxelShape::kLine;
  } else if (variances(0) < 0.1 * variances(1)) {
    *shape = VoxelShape::kPlane;
    *normal = solver.eigenvectors().col(0);
  }
}

}  // namespace

template <typename Visit>
void VoxelHashMap::ForEachVoxelAround(const Eigen::Vector3d& point, const Visit& visit) const {
  const Eigen::Vector3i centre = VoxelOf(point);
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = voxels_.find(centre + Eigen::Vector3i(dx, dy, dz));
        if (it != voxels_.end()) visit(it->second);
      }
    }
  }
}

void VoxelHashMap::ClassifyNeighbourhood(MapNeighbor* neighbor) const {
  const double squared_radius = voxel_size_ * voxel_size_;
  PointMoments moments(neighbor->point);
  ForEachVoxelAround(neighbor->point, [&](const Voxel& voxel) {
    for (const Eigen::Vector3d& point : voxel.points) {
      if ((point - neighbor->point).squaredNorm() <= squared_radius) moments.Add(point);
    }
  });
  ClassifyShape(moments, &neighbor->shape, &neighbor->normal);
}

void VoxelHashMap::Update(const std::vector<Eigen::Vector3d>& points_in_world,
                          const Eigen::Vector3d& origin) {
  std::vector<Voxel*> changed;
  for (const Eigen::Vector3d& point : points_in_world) {
    Voxel& voxel = voxels_[VoxelOf(point)];
    if (voxel.points.size() >= max_points_per_voxel_) continue;
    if (!voxel.changed) {
      voxel.changed = true;
      changed.push_back(&voxel);
    }
    voxel.points.push_back(point);
  }
  for (Voxel* voxel : changed) {
    PointMoments moments(voxel->points.front());
    for (const Eigen::Vector3d& point : voxel->points) moments.Add(point);
    ClassifyShape(moments, &voxel->shape, &voxel->normal);
    voxel->changed = false;
  }
  const double max_squared = max_distance_ * max_distance_;
  for (auto it = voxels_.begin(); it != voxels_.end();) {
    if ((it->second.points.front() - origin).squaredNorm() > max_squared) {
      it = voxels_.erase(it);
    } else {
      ++it;
    }
  }
}

bool VoxelHashMap::NearestNeighbor(const Eigen::Vector3d& query, MapNeighbor* neighbor) const {
  double best = std::numeric_limits<double>::infinity();
  const Voxel* best_voxel = nullptr;
  ForEachVoxelAround(query, [&](const Voxel& voxel) {
    for (const Eigen::Vector3d& point : voxel.points) {
      const double squared = (point - query).squaredNorm();
      if (squared < best) {
        best = squared;
        neighbor->point = point;
        best_voxel = &voxel;
      }
    }
  });
  if (best_voxel == nullptr) return false;
  neighbor->distance = std::sqrt(best);
  neighbor->shape = best_voxel->shape;
  neighbor->normal = best_voxel->normal;
  return true;
}

std::vector<Eigen::Vector3d> FirstPointPerVoxel(const std::vector<Eigen::Vector3d>& points,
                                                double voxel_size) {
  if (!(voxel_size > 0)) throw std::invalid_argument("FirstPointPerVoxel: voxel size must be > 0");
  std::unordered_set<Eigen::Vector3i, Hash> occupied;
  occupied.reserve(points.size());
  std::vector<Eigen::Vector3d> kept;
  for (const Eigen::Vector3d& point : points) {
    if (occupied.insert(VoxelIndex(point, voxel_size)).second) kept.push_back(point);
  }
  return kept;
}

}  // namespace colmap_lidar
