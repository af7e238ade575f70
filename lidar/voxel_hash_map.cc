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

void VoxelHashMap::ClassifyPoint(Voxel* voxel, int index) const {
  const Eigen::Vector3d& centre = voxel->points[index];
  const double squared_radius = voxel_size_ * voxel_size_;
  PointMoments moments(centre);
  ForEachVoxelAround(centre, [&](const Voxel& other) {
    for (const Eigen::Vector3d& point : other.points) {
      if ((point - centre).squaredNorm() <= squared_radius) moments.Add(point);
    }
  });
  PointShape& shape = voxel->point_shapes[index];
  ClassifyShape(moments, &shape.shape, &shape.normal);
  shape.generation = voxel->generation;
}

void VoxelHashMap::ClassifyNeighbourhoods(std::vector<MapNeighbor>* neighbors) {
  std::vector<std::pair<Voxel*, int>> stale;
  for (const MapNeighbor& neighbor : *neighbors) {
    if (neighbor.index < 0) continue;
    Voxel& voxel = voxels_.at(neighbor.voxel);
    voxel.point_shapes.resize(voxel.points.size());
    PointShape& shape = voxel.point_shapes[neighbor.index];
    if (shape.generation == voxel.generation || shape.queued) continue;
    shape.queued = true;
    stale.emplace_back(&voxel, neighbor.index);
  }
  // Each item writes its own point's shape and cannot throw: a plain static loop.
#pragma omp parallel for schedule(static)
  for (long i = 0; i < static_cast<long>(stale.size()); ++i) {
    ClassifyPoint(stale[i].first, stale[i].second);
    stale[i].first->point_shapes[stale[i].second].queued = false;
  }
  for (MapNeighbor& neighbor : *neighbors) {
    if (neighbor.index < 0) continue;
    const PointShape& shape = voxels_.at(neighbor.voxel).point_shapes[neighbor.index];
    neighbor.shape = shape.shape;
    neighbor.normal = shape.normal;
  }
}

void VoxelHashMap::InvalidateAround(const Eigen::Vector3i& key) {
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = voxels_.find(key + Eigen::Vector3i(dx, dy, dz));
        if (it != voxels_.end()) ++it->second.generation;
      }
    }
  }
}

void VoxelHashMap::Update(const std::vector<Eigen::Vector3d>& points_in_world,
                          const Eigen::Vector3d& origin) {
  std::vector<Eigen::Vector3i> changed;
  for (const Eigen::Vector3d& point : points_in_world) {
    const Eigen::Vector3i key = VoxelOf(point);
    Voxel& voxel = voxels_[key];
    if (voxel.points.size() >= max_points_per_voxel_) continue;
    if (!voxel.changed) {
      voxel.changed = true;
      changed.push_back(key);
    }
    voxel.points.push_back(point);
  }
  for (const Eigen::Vector3i& key : changed) {
    Voxel& voxel = voxels_.at(key);
    PointMoments moments(voxel.points.front());
    for (const Eigen::Vector3d& point : voxel.points) moments.Add(point);
    ClassifyShape(moments, &voxel.shape, &voxel.normal);
    voxel.changed = false;
    InvalidateAround(key);
  }
  const double max_squared = max_distance_ * max_distance_;
  std::vector<Eigen::Vector3i> dropped;
  for (auto it = voxels_.begin(); it != voxels_.end();) {
    if ((it->second.points.front() - origin).squaredNorm() > max_squared) {
      dropped.push_back(it->first);
      it = voxels_.erase(it);
    } else {
      ++it;
    }
  }
  for (const Eigen::Vector3i& key : dropped) InvalidateAround(key);
}

bool VoxelHashMap::NearestNeighbor(const Eigen::Vector3d& query, MapNeighbor* neighbor) const {
  double best = std::numeric_limits<double>::infinity();
  const Voxel* best_voxel = nullptr;
  int best_index = -1;
  const auto visit = [&](const Eigen::Vector3i& key) {
    const auto it = voxels_.find(key);
    if (it == voxels_.end()) return;
    const Voxel& voxel = it->second;
    for (size_t k = 0; k < voxel.points.size(); ++k) {
      const double squared = (voxel.points[k] - query).squaredNorm();
      if (squared < best) {
        best = squared;
        neighbor->point = voxel.points[k];
        best_voxel = &voxel;
        best_index = static_cast<int>(k);
      }
    }
  };
  // The query's own voxel first; then a voxel around only where it can hold a nearer point (its
  // box nearer than the best so far), which leaves most of the 26 unvisited.
  const Eigen::Vector3i centre = VoxelOf(query);
  visit(centre);
  const Eigen::Vector3d below = query - voxel_size_ * centre.cast<double>();
  const Eigen::Vector3d above = Eigen::Vector3d::Constant(voxel_size_) - below;
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        const Eigen::Vector3i step(dx, dy, dz);
        double gap = 0;
        for (int axis = 0; axis < 3; ++axis) {
          if (step[axis] != 0) gap += std::pow(step[axis] < 0 ? below[axis] : above[axis], 2);
        }
        if (!step.isZero() && gap < best) visit(centre + step);
      }
    }
  }
  if (best_voxel == nullptr) return false;
  neighbor->distance = std::sqrt(best);
  neighbor->voxel = VoxelOf(neighbor->point);
  neighbor->index = best_index;
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
