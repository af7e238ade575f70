#include "bridge/simulation/box_hierarchy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <random>
#include <set>

namespace colmap_lidar {
namespace sim {
namespace {

std::vector<AxisAlignedBox> RandomBoxes(int count, std::mt19937* rng) {
  std::uniform_real_distribution<double> position(-50, 50), size(1, 20);
  std::vector<AxisAlignedBox> boxes;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d lower(position(*rng), position(*rng), position(*rng));
    boxes.push_back({lower, lower + Eigen::Vector3d(size(*rng), size(*rng), size(*rng))});
  }
  return boxes;
}

// Every box a ray meets is visited (none is lost to the hierarchy); a leaf's other box may be
// visited too, but a small part of all boxes is.
TEST(BoxHierarchyTest, VisitsEveryBoxARayMeets) {
  std::mt19937 rng(11);
  const std::vector<AxisAlignedBox> boxes = RandomBoxes(300, &rng);
  const BoxHierarchy hierarchy(boxes);
  std::normal_distribution<double> normal(0, 1);
  std::uniform_real_distribution<double> position(-60, 60);
  size_t met = 0, visits = 0;
  for (int r = 0; r < 2000; ++r) {
    const Eigen::Vector3d origin(position(rng), position(rng), position(rng));
    Eigen::Vector3d direction(normal(rng), normal(rng), r % 10 == 0 ? 0.0 : normal(rng));
    direction.normalize();
    const double max_t = r % 2 == 0 ? 1e3 : 20.0;
    std::set<int> expected, visited;
    for (int i = 0; i < static_cast<int>(boxes.size()); ++i) {
      if (RayMeetsBox(boxes[i], origin, direction, max_t)) expected.insert(i);
    }
    hierarchy.Traverse(
        origin, direction, [&] { return max_t; }, [&](int i) { visited.insert(i); });
    met += expected.size();
    visits += visited.size();
    ASSERT_TRUE(std::includes(visited.begin(), visited.end(), expected.begin(), expected.end()))
        << "ray " << r;
  }
  EXPECT_GT(met, 2000u);  // the rays do meet boxes
  EXPECT_LT(visits, 2000 * boxes.size() / 10);
  std::cout << met << " boxes met, " << visits << " visited, of " << 2000 * boxes.size()
            << std::endl;
}

TEST(BoxHierarchyTest, EmptyAndSingle) {
  int visits = 0;
  BoxHierarchy().Traverse(
      Eigen::Vector3d::Zero(),
      Eigen::Vector3d::UnitX(),
      [] { return 1e3; },
      [&](int) { ++visits; });
  EXPECT_EQ(visits, 0);
  const BoxHierarchy single({{Eigen::Vector3d(5, -1, -1), Eigen::Vector3d(6, 1, 1)}});
  single.Traverse(
      Eigen::Vector3d::Zero(),
      Eigen::Vector3d::UnitX(),
      [] { return 1e3; },
      [&](int) { ++visits; });
  EXPECT_EQ(visits, 1);
  single.Traverse(
      Eigen::Vector3d::Zero(),
      Eigen::Vector3d::UnitX(),
      [] { return 4.0; },
      [&](int) { ++visits; });
  EXPECT_EQ(visits, 1);  // beyond max_t
}

}  // namespace
}  // namespace sim
}  // namespace colmap_lidar
