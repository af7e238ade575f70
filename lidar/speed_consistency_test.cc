#include "lidar/speed_consistency.h"

#include <gtest/gtest.h>

namespace colmap_lidar {
namespace {

RelativePose Edge(size_t target, size_t source, double forward_m) {
  RelativePose edge{target, source};
  edge.target_from_source.translation() = Eigen::Vector3d(forward_m, 0.02, -0.01);
  return edge;
}

// A car at 0.7 m per frame: edges to the next and the one after. Two consecutive sweeps whose ICP
// slid to almost no motion, and an edge over two frames that slid to 0.3 m per frame (57 % off), are
// refused; a car braking to 0.45 m per frame over ten frames is not.
TEST(SpeedConsistency, RefusesEdgesThatSlidAlongTheStreet) {
  std::vector<double> frames;
  std::vector<RelativePose> edges;
  for (size_t i = 0; i < 30; ++i) frames.push_back(static_cast<double>(i));
  auto speed = [](size_t i) { return i < 20 ? 0.7 : 0.7 - 0.025 * (i - 20); };
  for (size_t i = 0; i + 1 < 30; ++i) {
    edges.push_back(Edge(i, i + 1, speed(i)));
    if (i + 2 < 30) edges.push_back(Edge(i, i + 2, speed(i) + speed(i + 1)));
  }
  const size_t slid_12 = 2 * 12, slid_11_13 = 2 * 11 + 1, slid_13 = 2 * 13;
  edges[slid_12] = Edge(12, 13, 0.02);
  edges[slid_13] = Edge(13, 14, 0.03);
  edges[slid_11_13] = Edge(11, 13, 0.6);
  const SpeedCheck check = CheckSpeedConsistency(edges, frames, SpeedConsistencyOptions());
  std::vector<size_t> removed;
  for (size_t e = 0; e < edges.size(); ++e) {
    if (check.removed[e]) removed.push_back(e);
  }
  EXPECT_EQ(removed, (std::vector<size_t>{slid_11_13, slid_12, slid_13}));
  EXPECT_NE(check.reason[slid_12].find("inconsistent speed"), std::string::npos);
  // Where ICP starts again: the neighbours' velocity over the edge's frames.
  EXPECT_NEAR(check.predicted_translation[slid_12].x(), 0.7, 1e-9);
  EXPECT_NEAR(check.predicted_translation[slid_11_13].x(), 1.4, 1e-9);
  EXPECT_TRUE(check.predicted_translation[0].isZero());  // kept: no prediction
  EXPECT_TRUE(check.reason[0].empty());

  // Frames given by KITTI-style numbers (a step of 5): the speed is per frame period, and no edge
  // spans few enough frames to give the neighbours' speed.
  std::vector<double> stepped;
  for (double frame : frames) stepped.push_back(5 * frame);
  const SpeedCheck wide = CheckSpeedConsistency(edges, stepped, SpeedConsistencyOptions());
  EXPECT_EQ(std::count(wide.removed.begin(), wide.removed.end(), true), 0);
}

// An edge over eleven frames (a repeated structure matched 8 m off) is judged against the short
// edges around its middle; a loop closure, revisiting the start 29 frames later, is not judged.
TEST(SpeedConsistency, JudgesLongEdgesButNotLoopClosures) {
  std::vector<double> frames;
  std::vector<RelativePose> edges;
  for (size_t i = 0; i < 30; ++i) frames.push_back(static_cast<double>(i));
  for (size_t i = 0; i + 1 < 30; ++i) edges.push_back(Edge(i, i + 1, 0.7));
  edges.push_back(Edge(10, 21, 11 * 0.7 + 0.5));  // 7 % long: kept
  edges.push_back(Edge(12, 23, 16.0));            // 8 m off: refused
  edges.push_back(Edge(0, 29, 0.3));              // the loop closure
  const SpeedCheck check = CheckSpeedConsistency(edges, frames, SpeedConsistencyOptions());
  const size_t n = edges.size();
  EXPECT_FALSE(check.removed[n - 3]);
  EXPECT_TRUE(check.removed[n - 2]);
  EXPECT_NEAR(check.predicted_translation[n - 2].x(), 11 * 0.7, 1e-9);
  EXPECT_FALSE(check.removed[n - 1]);
}

TEST(SpeedConsistency, AWalkingPaceIsNotJudgedAndAStationWithoutFrameThrows) {
  std::vector<RelativePose> edges;
  for (size_t i = 0; i + 1 < 12; ++i) edges.push_back(Edge(i, i + 1, i == 6 ? 0.0 : 0.14));
  std::vector<double> frames(12);
  for (size_t i = 0; i < 12; ++i) frames[i] = static_cast<double>(i);
  const SpeedCheck check = CheckSpeedConsistency(edges, frames, SpeedConsistencyOptions());
  EXPECT_EQ(std::count(check.removed.begin(), check.removed.end(), true), 0);
  frames.pop_back();
  EXPECT_THROW(CheckSpeedConsistency(edges, frames, SpeedConsistencyOptions()),
               std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
