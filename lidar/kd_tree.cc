#include "lidar/kd_tree.h"

#include <nanoflann.hpp>

namespace colmap_lidar {
namespace {

struct VectorAdaptor {
  const std::vector<Eigen::Vector3d>& points;
  size_t kdtree_get_point_count() const { return points.size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return points[i][dim]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};

using Index =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, VectorAdaptor>,
                                        VectorAdaptor,
                                        3,
                                        size_t>;

}  // namespace

struct KdTree3::Impl {
  explicit Impl(const std::vector<Eigen::Vector3d>& points)
      : adaptor{points}, index(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    index.buildIndex();
  }
  VectorAdaptor adaptor;
  Index index;
};

KdTree3::KdTree3(const std::vector<Eigen::Vector3d>& points)
    : points_(points), impl_(std::make_unique<Impl>(points)) {}

KdTree3::~KdTree3() = default;

bool KdTree3::Nearest(const Eigen::Vector3d& query, size_t* index, double* squared_distance) const {
  if (points_.empty()) return false;
  nanoflann::KNNResultSet<double, size_t> result(1);
  result.init(index, squared_distance);
  impl_->index.findNeighbors(result, query.data(), nanoflann::SearchParams());
  return true;
}

void KdTree3::KNearest(const Eigen::Vector3d& query,
                       size_t k,
                       std::vector<size_t>* indices,
                       std::vector<double>* squared_distances) const {
  k = std::min(k, points_.size());
  indices->resize(k);
  squared_distances->resize(k);
  if (k == 0) return;
  const size_t n =
      impl_->index.knnSearch(query.data(), k, indices->data(), squared_distances->data());
  indices->resize(n);
  squared_distances->resize(n);
}

void KdTree3::RadiusSearch(const Eigen::Vector3d& query,
                           double radius,
                           std::vector<size_t>* indices) const {
  std::vector<std::pair<size_t, double>> matches;
  impl_->index.radiusSearch(
      query.data(), radius * radius, matches, nanoflann::SearchParams(32, 0, false));
  indices->resize(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) (*indices)[i] = matches[i].first;
}

}  // namespace colmap_lidar
