// Planted wrong edges in a pose graph of exact relative poses: the 3-cycle check removes exactly them
// and names the reason; noise below the tolerance removes nothing.
#include "lidar/cycle_consistency.h"

#include <gtest/gtest.h>

#include <random>

namespace colmap_lidar {
namespace {

Eigen::Isometry3d Pose(double yaw, const Eigen::Vector3d& t) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = t;
  return pose;
}

// A drive: 10 frames 0.5 m apart with a slow turn; edges between frames up to 3 apart.
std::vector<RelativePose> DriveEdges(double noise_m, uint64_t seed) {
  std::vector<Eigen::Isometry3d> world_from_lidar;
  for (int i = 0; i < 10; ++i) {
    world_from_lidar.push_back(Pose(0.03 * i, Eigen::Vector3d(0.5 * i, 0.02 * i * i, 0)));
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0, noise_m);
  std::vector<RelativePose> edges;
  for (size_t i = 0; i < world_from_lidar.size(); ++i) {
    for (size_t j = i + 1; j <= std::min(world_from_lidar.size() - 1, i + 3); ++j) {
      Eigen::Isometry3d measured = world_from_lidar[i].inverse() * world_from_lidar[j];
      measured.translation() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      edges.push_back({i, j, measured, 1.0});
    }
  }
  return edges;
}

TEST(CycleConsistency, RemovesPlantedWrongEdgesAndNamesTheReason) {
  std::vector<RelativePose> edges = DriveEdges(0.005, 1);
  // ICP slid along the street: 0.7 m along x on one edge, a wrong 4 deg turn on another.
  edges[4].target_from_source.translation().x() -= 0.7;
  edges[11].target_from_source.linear() =
      edges[11].target_from_source.linear() *
      Eigen::AngleAxisd(4 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const CycleCheck check = CheckThreeCycles(edges, CycleConsistencyOptions());
  EXPECT_GT(check.num_cycles, 10u);
  for (size_t e = 0; e < edges.size(); ++e) {
    EXPECT_EQ(check.removed[e], e == 4 || e == 11) << "edge " << e;
  }
  EXPECT_NE(check.reason[4].find("breaks"), std::string::npos) << check.reason[4];
  // What is left closes to the noise: 3 edges of 5 mm noise per axis.
  EXPECT_LT(check.worst_translation_m, 0.05);
}

TEST(CycleConsistency, KeepsEveryEdgeOfANoisyConsistentGraph) {
  const std::vector<RelativePose> edges = DriveEdges(0.02, 2);
  const CycleCheck check = CheckThreeCycles(edges, CycleConsistencyOptions());
  for (size_t e = 0; e < edges.size(); ++e) EXPECT_FALSE(check.removed[e]) << "edge " << e;
}

// Two measurements of one motion (an image edge and a LiDAR edge): the one that breaks the 2-cycle
// and the 3-cycles goes, the one the 3-cycles confirm stays; the 2-cycle alone cannot tell which is
// wrong, and the weaker edge goes, as in a lone 3-cycle.
TEST(CycleConsistency, ParallelEdgesFormTwoCycles) {
  std::vector<RelativePose> edges = DriveEdges(0.005, 4);
  RelativePose wrong = edges[0];  // frames 0-1, yawed 178 deg the wrong way
  wrong.target_from_source.linear() =
      wrong.target_from_source.linear() *
      Eigen::AngleAxisd(178 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  edges.push_back(wrong);
  const CycleCheck check = CheckThreeCycles(edges, CycleConsistencyOptions());
  for (size_t e = 0; e < edges.size(); ++e) {
    EXPECT_EQ(check.removed[e], e + 1 == edges.size()) << "edge " << e;
  }
  RelativePose strong_wrong = wrong;
  strong_wrong.weight = 2;
  const CycleCheck alone = CheckThreeCycles({edges[0], strong_wrong}, CycleConsistencyOptions());
  EXPECT_EQ(alone.num_cycles, 1u);
  EXPECT_TRUE(alone.removed[0]);
  EXPECT_FALSE(alone.removed[1]);
}

TEST(CycleConsistency, WithoutCyclesNothingCanBeJudged) {
  std::vector<RelativePose> edges = DriveEdges(0, 3);
  std::vector<RelativePose> chain;
  for (const RelativePose& e : edges) {
    if (e.source == e.target + 1) chain.push_back(e);
  }
  chain[2].target_from_source.translation().x() += 3.0;
  const CycleCheck check = CheckThreeCycles(chain, CycleConsistencyOptions());
  EXPECT_EQ(check.num_cycles, 0u);
  for (size_t e = 0; e < chain.size(); ++e) EXPECT_FALSE(check.removed[e]);
}

}  // namespace
}  // namespace colmap_lidar
