// A bounding volume hierarchy over axis-aligned boxes, one per item, for the simulator's ray
// queries: a ray visits the items whose boxes it passes through, in O(log n) nodes for most rays
// instead of testing every item. Built top down, each node split at the median of its items' box
// centres along its longest axis.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace colmap_lidar {
namespace sim {

struct AxisAlignedBox {
  Eigen::Vector3d lower = Eigen::Vector3d::Zero();
  Eigen::Vector3d upper = Eigen::Vector3d::Zero();
};

// Whether the ray origin + t * direction meets `box` at some t in [0, max_t) (slab test).
bool RayMeetsBox(const AxisAlignedBox& box,
                 const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& direction,
                 double max_t);

class BoxHierarchy {
 public:
  BoxHierarchy() = default;
  explicit BoxHierarchy(const std::vector<AxisAlignedBox>& boxes);

  // Calls visit(item) for the items whose boxes the ray meets before max_t(), a callable read at
  // every node (a closest-hit query shrinks it as it finds hits); every item the ray meets before
  // the final max_t() is visited. The order of the visits is not the items' order.
  template <typename MaxT, typename Visit>
  void Traverse(const Eigen::Vector3d& origin,
                const Eigen::Vector3d& direction,
                const MaxT& max_t,
                const Visit& visit) const {
    if (nodes_.empty()) return;
    int stack[64];
    int size = 0;
    stack[size++] = 0;
    while (size > 0) {
      const Node& node = nodes_[stack[--size]];
      if (!RayMeetsBox(node.box, origin, direction, max_t())) continue;
      if (node.left < 0) {
        for (int k = node.first; k < node.first + node.count; ++k) visit(items_[k]);
        continue;
      }
      stack[size++] = node.right;
      stack[size++] = node.left;
    }
  }

 private:
  struct Node {
    AxisAlignedBox box;
    int left = -1, right = -1;  // children; -1: a leaf holding items_[first, first + count)
    int first = 0, count = 0;
  };
  int Build(const std::vector<AxisAlignedBox>& boxes, int first, int count);

  std::vector<Node> nodes_;
  std::vector<int> items_;
};

}  // namespace sim
}  // namespace colmap_lidar
