#include "bridge/initialization/edge_consistency.h"

#include <gtest/gtest.h>

namespace colmap_lidar {
namespace {

colmap::Rigid3d TurnAboutZ(double degrees) {
  return colmap::Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d::UnitZ())),
      Eigen::Vector3d(1, 0, 0));
}

// The LiDAR turns about another axis than the camera (a tilted mount): only the angle is compared.
colmap::Rigid3d TurnAboutX(double degrees) {
  return colmap::Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(0, 0, 1));
}

TEST(EdgeConsistency, DropsLidarEdgesThatContradictTheImagesDirectlyOrThroughAChain) {
  // Image edges 1-2 and 2-3, each a 60 deg turn; station 4 has no image edge.
  const ImageEdges images = {{{1, 2}, TurnAboutZ(60)}, {{2, 3}, TurnAboutZ(60)}};
  const std::map<colmap::image_t, std::string> names = {{1, "a"}, {2, "b"}, {3, "c"}, {4, "d"}};
  const std::vector<LidarStationEdge> lidar = {
      {2, 1, TurnAboutX(61), 10},   // the direct image edge agrees within 5 deg: kept
      {1, 3, TurnAboutX(118), 10},  // the chain 1-2-3 (120 deg) agrees: kept
      {1, 3, TurnAboutX(1), 10},    // slid on the ground: contradicted by the chain
      {2, 3, TurnAboutX(170), 10},  // contradicted by the direct edge
      {3, 4, TurnAboutX(5), 10},    // nothing to compare with: the LiDAR bridges, kept
  };
  std::vector<std::string> contradicted;
  const std::vector<LidarStationEdge> kept =
      DropContradictedLidarEdges(images, lidar, names, 5.0, &contradicted);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0].image_i, 2u);
  EXPECT_NEAR(
      Eigen::AngleAxisd(kept[1].lidar_i_from_lidar_j.rotation).angle(), 118 * M_PI / 180, 1e-9);
  EXPECT_EQ(kept[2].image_j, 4u);
  ASSERT_EQ(contradicted.size(), 2u);
  EXPECT_EQ(contradicted[0], "a c: LiDAR 1.0 deg, images 120.0 deg");
  EXPECT_EQ(contradicted[1], "b c: LiDAR 170.0 deg, images 60.0 deg");
}

TEST(EdgeConsistency, AChainedComparisonAllowsAQuarterDegreePerEdge) {
  // A chain of 4 edges of 10 deg (depths 0 and 4 from the first station): bound 5 + 0.25 * 4 = 6 deg.
  ImageEdges images;
  for (colmap::image_t i = 1; i <= 4; ++i) images[{i, i + 1}] = TurnAboutZ(10);
  const std::map<colmap::image_t, std::string> names = {
      {1, "1"}, {2, "2"}, {3, "3"}, {4, "4"}, {5, "5"}};
  std::vector<std::string> contradicted;
  EXPECT_EQ(
      DropContradictedLidarEdges(images, {{1, 5, TurnAboutX(45.5), 1}}, names, 5.0, &contradicted)
          .size(),
      1u);
  EXPECT_TRUE(
      DropContradictedLidarEdges(images, {{1, 5, TurnAboutX(46.5), 1}}, names, 5.0, &contradicted)
          .empty());
}

}  // namespace
}  // namespace colmap_lidar
