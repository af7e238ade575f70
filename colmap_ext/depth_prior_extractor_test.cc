#include "colmap_ext/depth_prior_extractor.h"

#include <gtest/gtest.h>

namespace colmap_lidar {
namespace {

// A ramp: depth = 2 + 0.001 * col at the centre of pixel (col, row), left half only.
colmap::mvs::DepthMap HalfRamp() {
  colmap::mvs::DepthMap map(40, 30, 0.f, 3.f);
  for (int row = 0; row < 30; ++row) {
    for (int col = 0; col < 40; ++col) {
      map.Set(row, col, col < 20 ? 2.f + 0.001f * col : 0.f);
    }
  }
  return map;
}

TEST(DepthAtKeypoint, InterpolatesBilinearlyInsideAValidQuad) {
  const colmap::mvs::DepthMap map = HalfRamp();
  DepthPriorOptions options;
  // x = 10.5 + 0.3 lies 0.3 px right of the centre of column 10.
  const std::optional<double> depth = DepthAtKeypoint(map, 10.8, 5.5, options);
  ASSERT_TRUE(depth);
  EXPECT_NEAR(*depth, 2.0 + 0.001 * 10.3, 1e-6);
}

TEST(DepthAtKeypoint, TakesTheNearestValidPixelWithinTheRadius) {
  const colmap::mvs::DepthMap map = HalfRamp();
  DepthPriorOptions options;
  options.max_radius_px = 2;
  // Keypoint at x = 21.2: the last valid column 19 has its centre at 19.5, 1.7 px away.
  const std::optional<double> depth = DepthAtKeypoint(map, 21.2, 5.5, options);
  ASSERT_TRUE(depth);
  EXPECT_NEAR(*depth, 2.0 + 0.001 * 19, 1e-6);
  // 2.3 px away: no prior.
  EXPECT_FALSE(DepthAtKeypoint(map, 21.8, 5.5, options));
  options.max_radius_px = 3;
  EXPECT_TRUE(DepthAtKeypoint(map, 21.8, 5.5, options));
}

TEST(DepthAtKeypoint, NeverBlendsAcrossADepthEdge) {
  colmap::mvs::DepthMap map(10, 10, 0.f, 5.f);
  for (int row = 0; row < 10; ++row) {
    for (int col = 0; col < 10; ++col) map.Set(row, col, col < 5 ? 2.f : 4.f);
  }
  DepthPriorOptions options;
  const std::optional<double> near_side = DepthAtKeypoint(map, 4.9, 3.5, options);
  const std::optional<double> far_side = DepthAtKeypoint(map, 5.1, 3.5, options);
  ASSERT_TRUE(near_side && far_side);
  EXPECT_DOUBLE_EQ(*near_side, 2.0);
  EXPECT_DOUBLE_EQ(*far_side, 4.0);
}

TEST(DepthSigma, IsTheSeedsFormula) {
  // sigma_d = d^2 / (b f) sigma_p: 2.5 m, 0.38 m, 1154 px, 1 px -> 14.25 mm.
  EXPECT_NEAR(DepthSigma(2.5, 0.38, 1154, 1.0), 6.25 / (0.38 * 1154), 1e-12);
  EXPECT_NEAR(DepthSigma(2.5, 0.38, 1154, 0.5), 0.5 * 6.25 / (0.38 * 1154), 1e-12);
}

TEST(ExtractDepthPriors, KeepsKeypointIndicesAndSkipsKeypointsWithoutDepth) {
  const colmap::mvs::DepthMap map = HalfRamp();
  colmap::FeatureKeypoints keypoints = {colmap::FeatureKeypoint(5.5, 5.5),
                                        colmap::FeatureKeypoint(35.0, 5.0),
                                        colmap::FeatureKeypoint(12.5, 20.5)};
  const std::vector<DepthPrior> priors =
      ExtractDepthPriors(keypoints, map, 0.38, 1000, DepthPriorOptions());
  ASSERT_EQ(priors.size(), 2u);
  EXPECT_EQ(priors[0].point2D_idx, 0u);
  EXPECT_EQ(priors[1].point2D_idx, 2u);
  EXPECT_NEAR(priors[1].depth, 2.012, 1e-6);
  EXPECT_NEAR(priors[1].sigma, 2.012 * 2.012 / 380, 1e-6);
}

}  // namespace
}  // namespace colmap_lidar
