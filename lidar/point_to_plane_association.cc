#include "lidar/point_to_plane_association.h"

#include "lidar/util/check_option.h"

#include <algorithm>
#include <numeric>
#include <random>
#include <stdexcept>

namespace colmap_lidar {

namespace {

// The first `num` of a seeded random permutation of 0..size-1 (partial Fisher-Yates shuffle).
std::vector<size_t> UniformSample(size_t size, size_t num, uint64_t seed) {
  std::vector<size_t> order(size);
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(seed);
  num = std::min(num, size);
  for (size_t i = 0; i < num; ++i) {
    std::uniform_int_distribution<size_t> pick(i, size - 1);
    std::swap(order[i], order[pick(rng)]);
  }
  order.resize(num);
  return order;
}

// Bucket of a normal direction (n and -n alike): the dominant axis, then a 4 x 4 grid over the other
// two components of the normal flipped so that the dominant one is positive. 48 buckets.
int NormalBucket(const Eigen::Vector3d& normal) {
  int axis = 0;
  normal.cwiseAbs().maxCoeff(&axis);
  const Eigen::Vector3d n = normal[axis] < 0 ? Eigen::Vector3d(-normal) : normal;
  const auto cell = [](double value) {
    return std::clamp(static_cast<int>((value + 1) * 2), 0, 3);
  };
  return axis * 16 + cell(n[(axis + 1) % 3]) * 4 + cell(n[(axis + 2) % 3]);
}

// Up to `num` points drawn round-robin over the normal buckets, at random within each.
// Points above `max_curvature` (if curvatures are given) are left out.
std::vector<size_t> NormalSpaceSample(const PointCloud& cloud,
                                      const std::vector<double>* curvature,
                                      double max_curvature,
                                      size_t num,
                                      uint64_t seed) {
  std::vector<std::vector<size_t>> buckets(48);
  for (size_t i = 0; i < cloud.Size(); ++i) {
    if (cloud.normals[i].squaredNorm() < 0.5 || (curvature && (*curvature)[i] > max_curvature)) {
      continue;
    }
    buckets[NormalBucket(cloud.normals[i])].push_back(i);
  }
  std::mt19937_64 rng(seed);
  for (std::vector<size_t>& bucket : buckets) std::shuffle(bucket.begin(), bucket.end(), rng);
  std::vector<size_t> order;
  order.reserve(std::min(num, cloud.Size()));
  for (size_t round = 0; order.size() < num; ++round) {
    bool any = false;
    for (const std::vector<size_t>& bucket : buckets) {
      if (round >= bucket.size() || order.size() == num) continue;
      order.push_back(bucket[round]);
      any = true;
    }
    if (!any) break;
  }
  return order;
}

}  // namespace

bool AssociationOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(num_samples, 0);
  LIDAR_CHECK_OPTION_GT(max_distance, 0);
  LIDAR_CHECK_OPTION_GT(max_curvature, 0);
  return true;
}

std::vector<PointToPlaneObservation> AssociatePointToPlane(
    const PointCloud& source,
    const PointCloud& target,
    const KdTree3& target_tree,
    const Eigen::Isometry3d& target_from_source,
    const AssociationOptions& options,
    const AssociationCurvatures& curvatures) {
  const std::vector<double>* target_curvature = curvatures.target;
  const std::vector<double>* source_curvature = curvatures.source;
  ThrowUnlessValid(options, "AssociationOptions");
  if (!target.HasNormals())
    throw std::invalid_argument("AssociatePointToPlane: target needs normals");
  if (target_tree.Size() != target.Size()) {
    throw std::invalid_argument("AssociatePointToPlane: the k-d tree is not built over the target");
  }
  if (source_curvature && source_curvature->size() != source.Size()) {
    throw std::invalid_argument("AssociatePointToPlane: one curvature per source point expected");
  }
  if (target_curvature && target_curvature->size() != target.Size()) {
    throw std::invalid_argument("AssociatePointToPlane: one curvature per target point expected");
  }
  const std::vector<size_t> order =
      options.normal_space_sampling && source.HasNormals()
          ? NormalSpaceSample(
                source, source_curvature, options.max_curvature, options.num_samples, options.seed)
          : UniformSample(source.Size(), options.num_samples, options.seed);
  const size_t num = order.size();
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
