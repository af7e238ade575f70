#include "bridge/joint/term_pulls.h"

#include <gtest/gtest.h>

namespace colmap_lidar {
namespace {

TermPull Pull(const std::string& term, int axis, double pull, double significance) {
  TermPull result;
  result.term = term;
  result.pull[axis] = pull;
  result.significance[axis] = significance;
  return result;
}

// The pulls in units of each axis' reported sigma; undetermined axes have neither that nor a t.
TEST(SetPullSigmas, DividesByTheSigmaAndZeroesUndeterminedAxes) {
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  covariance.diagonal() << 0.01, 0.04, 0.01, 4, 4, 0;
  std::vector<TermPull> pulls = {Pull("lidar", 1, 0.4, 5), Pull("reprojection", 5, 3, 7)};
  SetPullSigmas(covariance, {false, false, false, false, false, true}, &pulls);
  EXPECT_DOUBLE_EQ(pulls[0].pull_sigmas[1], 2.0);
  EXPECT_DOUBLE_EQ(pulls[0].significance[1], 5.0);
  EXPECT_DOUBLE_EQ(pulls[1].pull_sigmas[5], 0.0);
  EXPECT_DOUBLE_EQ(pulls[1].significance[5], 0.0);
}

// Two terms significant in opposite directions on one axis disagree; one significant term alone,
// or two on the same side, do not.
TEST(DescribeTermDisagreements, NamesOnlyOppositeSignificantPulls) {
  std::vector<TermPull> pulls = {Pull("reprojection", 0, -0.01, -25.9),
                                 Pull("lidar", 0, 0.01, 11.9),
                                 Pull("landmark_lidar", 0, 0.001, 0.7)};
  pulls[2].significance[4] = 8;  // alone on ty
  pulls[1].significance[2] = 4;  // rz: both positive
  pulls[0].significance[2] = 3.5;
  const std::vector<std::string> sentences = DescribeTermDisagreements(pulls);
  ASSERT_EQ(sentences.size(), 1u);
  EXPECT_NE(sentences[0].find("the lidar and reprojection terms"), std::string::npos);
  EXPECT_NE(sentences[0].find("rotation about the camera x axis"), std::string::npos);
  EXPECT_NE(sentences[0].find("t = +11.9 and -25.9"), std::string::npos) << sentences[0];

  pulls[1].significance[0] = 2.9;  // below the threshold
  EXPECT_TRUE(DescribeTermDisagreements(pulls).empty());
}

}  // namespace
}  // namespace colmap_lidar
