#include "lidar/point_to_plane_association.h"

#include <algorithm>
#include <numeric>
#include <random>
#include <stdexcept>

namespace colmap_lidar {

bool AssociationOptions::Check() const {
  if (num_samples == 0 || !(max_distance > 0) || !(max_curvature > 0)) {
    throw std::invalid_argument(
        "AssociationOptions: num_samples, max_distance and max_curvature must "
        "be > 0");
  }
  return true;
}

std::vector<PointToPlaneObservation> AssociatePointToPlane(
    const PointCloud& source,
    const PointCloud& target,
    const KdTree3& target_tree,
    const Eigen::Isometry3d& target_from_source,
    const AssociationOptions& options,
    const std::vector<double>* target_curvature) {
  options.Check();
  if (!target.HasNormals())
    throw std::invalid_argument("AssociatePointToPlane: target needs normals");
  if (target_tree.Size() != target.Size()) {
    throw std::invalid_argument("AssociatePointToPlane: the k-d tree is not built over the target");
  }
  if (target_curvature && target_curvature->size() != target.Size()) {
    throw std::invalid_argument("AssociatePointToPlane: one curvature per target point expected");
  }
  // A seeded partial Fisher-Yates shuffle: the first num_samples of a random permutation.
  std::vector<size_t> order(source.Size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(options.seed);
  const size_t num = std::min(options.num_samples, order.size());
  for (size_t i = 0; i < num; ++i) {
    std::uniform_int_distribution<size_t> pick(i, order.size() - 1);
    std::swap(order[i], order[pick(rng)]);
  }
  std::vector<PointToPlaneObservation> observations;
  observations.reserve(num);
  const double max_squared = options.max_distance * options.max_distance;
  for (size_t k = 0; k < num; ++k) {
    const Eigen::Vector3d& p = source.points[order[k]];
    size_t index;
    double squared;
    if (!target_tree.Nearest(target_from_source * p, &index, &squared) || squared > max_squared) {
      continue;
    }
    const Eigen::Vector3d& n = target.normals[index];
    if (n.squaredNorm() < 0.5) continue;
    if (target_curvature && (*target_curvature)[index] > options.max_curvature) continue;
    observations.push_back({p, target.points[index], n});
  }
  return observations;
}

}  // namespace colmap_lidar
