#include "bridge/hand_eye.h"

#include <gtest/gtest.h>

#include <cmath>

namespace colmap_lidar {
namespace {

colmap::Rigid3d Motion(double angle_deg,
                       const Eigen::Vector3d& axis,
                       const Eigen::Vector3d& translation) {
  return colmap::Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(angle_deg * M_PI / 180, axis.normalized())),
      translation);
}

const colmap::Rigid3d kCamFromLidar = Motion(97, {0.3, -0.7, 0.6}, {0.19, -0.25, -0.05});

// B = X^-1 A X for each camera motion A.
std::vector<HandEyeMotion> Conjugate(const std::vector<colmap::Rigid3d>& camera_motions) {
  std::vector<HandEyeMotion> motions;
  for (const colmap::Rigid3d& a : camera_motions) {
    motions.push_back({a, colmap::Inverse(kCamFromLidar) * a * kCamFromLidar});
  }
  return motions;
}

TEST(HandEye, RecoversTheExtrinsicFromMotionsAboutTwoAxes) {
  const HandEyeResult result =
      SolveHandEye(Conjugate({Motion(40, {0, 1, 0.05}, {1.2, 0.1, 0.4}),
                              Motion(-70, {0.02, 1, -0.03}, {-0.8, 0.05, 1.1}),
                              Motion(25, {1, 0.2, 0}, {0.1, -0.6, 0.3})}),
                   HandEyeOptions());
  ASSERT_TRUE(result.unique) << result.message;
  EXPECT_EQ(result.num_motions, 3);
  EXPECT_LT(result.cam_from_lidar.rotation.angularDistance(kCamFromLidar.rotation), 1e-9);
  EXPECT_LT((result.cam_from_lidar.translation - kCamFromLidar.translation).norm(), 1e-9);
}

TEST(HandEye, SaysWhyMotionAboutOneAxisOrNoneIsDegenerate) {
  const HandEyeResult one_axis =
      SolveHandEye(Conjugate({Motion(40, {0, 1, 0}, {1.2, 0.1, 0.4}),
                              Motion(-70, {0, 1, 0}, {-0.8, 0.05, 1.1})}),
                   HandEyeOptions());
  EXPECT_FALSE(one_axis.unique);
  EXPECT_NE(one_axis.message.find("rotation axes within 0.0 deg"), std::string::npos)
      << one_axis.message;
  const HandEyeResult translations = SolveHandEye(
      Conjugate({Motion(0, {0, 1, 0}, {1.2, 0.1, 0.4}), Motion(0, {0, 1, 0}, {-0.8, 0.05, 1.1})}),
      HandEyeOptions());
  EXPECT_FALSE(translations.unique);
  EXPECT_NE(translations.message.find("0 rotating motion pairs"), std::string::npos)
      << translations.message;
}

}  // namespace
}  // namespace colmap_lidar
