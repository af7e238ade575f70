#include "bridge/simulation/box_hierarchy.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace colmap_lidar {
namespace sim {

bool RayMeetsBox(const AxisAlignedBox& box,
                 const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& direction,
                 double max_t) {
  constexpr double kParallel = 1e-9;
  double t_min = -1e300, t_max = 1e300;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(direction[i]) < kParallel) {
      if (origin[i] < box.lower[i] || origin[i] > box.upper[i]) return false;
      continue;
    }
    double t1 = (box.lower[i] - origin[i]) / direction[i];
    double t2 = (box.upper[i] - origin[i]) / direction[i];
    if (t1 > t2) std::swap(t1, t2);
    t_min = std::max(t_min, t1);
    t_max = std::min(t_max, t2);
  }
  return t_min <= t_max && t_max >= 0 && t_min < max_t;
}

BoxHierarchy::BoxHierarchy(const std::vector<AxisAlignedBox>& boxes) {
  items_.resize(boxes.size());
  std::iota(items_.begin(), items_.end(), 0);
  if (!boxes.empty()) Build(boxes, 0, static_cast<int>(boxes.size()));
}

int BoxHierarchy::Build(const std::vector<AxisAlignedBox>& boxes, int first, int count) {
  constexpr int kLeafSize = 2;
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  AxisAlignedBox bounds{Eigen::Vector3d::Constant(1e300), Eigen::Vector3d::Constant(-1e300)};
  for (int k = first; k < first + count; ++k) {
    bounds.lower = bounds.lower.cwiseMin(boxes[items_[k]].lower);
    bounds.upper = bounds.upper.cwiseMax(boxes[items_[k]].upper);
  }
  nodes_[index].box = bounds;
  nodes_[index].first = first;
  nodes_[index].count = count;
  if (count <= kLeafSize) return index;
  int axis = 0;
  (bounds.upper - bounds.lower).maxCoeff(&axis);
  const auto begin = items_.begin() + first;
  std::nth_element(begin, begin + count / 2, begin + count, [&](int a, int b) {
    const double ca = boxes[a].lower[axis] + boxes[a].upper[axis];
    const double cb = boxes[b].lower[axis] + boxes[b].upper[axis];
    return ca < cb || (ca == cb && a < b);
  });
  const int left = Build(boxes, first, count / 2);
  const int right = Build(boxes, first + count / 2, count - count / 2);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

}  // namespace sim
}  // namespace colmap_lidar
