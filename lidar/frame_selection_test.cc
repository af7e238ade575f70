#include "lidar/frame_selection.h"

#include <gtest/gtest.h>

#include <cmath>

namespace colmap_lidar {
namespace {

// A drive along x at `step_m` per frame that stands still for frames [stop_begin, stop_end).
std::vector<Eigen::Isometry3d> DriveWithStop(int num_frames,
                                             double step_m,
                                             int stop_begin,
                                             int stop_end) {
  std::vector<Eigen::Isometry3d> poses;
  double x = 0;
  for (int i = 0; i < num_frames; ++i) {
    if (i > 0 && (i <= stop_begin || i >= stop_end)) x += step_m;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation().x() = x;
    poses.push_back(pose);
  }
  return poses;
}

TEST(FrameSelectionTest, AStandstillKeepsOneFrameAndMotionKeepsTheRest) {
  const auto poses = DriveWithStop(30, 1.0, 10, 20);
  const FrameSelection selection = SelectFrames(poses, FrameSelectionOptions());
  // Frames 0-10 move, 11-19 stand at frame 10's place, 20-29 move again.
  EXPECT_EQ(selection.kept.size(), 21u);
  for (int i = 11; i < 20; ++i) {
    EXPECT_EQ(selection.reasons[i], FrameSelectionReason::kLeftOut) << i;
  }
  EXPECT_EQ(selection.reasons[0], FrameSelectionReason::kFirst);
  EXPECT_EQ(selection.reasons[20], FrameSelectionReason::kDistance);
  EXPECT_EQ(selection.spacing_factor, 1);
}

TEST(FrameSelectionTest, ATurnOnTheSpotIsKeptByItsRotation) {
  std::vector<Eigen::Isometry3d> poses(10, Eigen::Isometry3d::Identity());
  for (int i = 0; i < 10; ++i) {
    poses[i].linear() = Eigen::AngleAxisd(i * 3.0 * M_PI / 180, Eigen::Vector3d::UnitZ()).matrix();
  }
  const FrameSelection selection = SelectFrames(poses, FrameSelectionOptions());
  // 3 deg per frame, 5 deg spacing: every second frame, and the last.
  EXPECT_EQ(selection.kept, (std::vector<int>{0, 2, 4, 6, 8, 9}));
  EXPECT_EQ(selection.reasons[2], FrameSelectionReason::kRotation);
  EXPECT_EQ(selection.reasons[9], FrameSelectionReason::kLast);
}

TEST(FrameSelectionTest, ALongDriveIsThinnedToTheCapWithEvenSpacing) {
  const auto poses = DriveWithStop(3000, 1.3, 0, 0);
  FrameSelectionOptions options;
  options.max_frames = 300;
  const FrameSelection selection = SelectFrames(poses, options);
  ASSERT_LE(selection.kept.size(), 300u);
  EXPECT_GE(selection.kept.size(), 270u);
  EXPECT_EQ(selection.kept.front(), 0);
  EXPECT_EQ(selection.kept.back(), 2999);
  // 3000 frames at 1.3 m within 300: every tenth frame would keep 301 with the last, so every
  // eleventh (274 frames, 14.3 m apart).
  EXPECT_GT(selection.spacing_factor * options.min_distance_m, 13.0);
  EXPECT_LE(selection.spacing_factor * options.min_distance_m, 14.3);
  for (size_t k = 1; k + 1 < selection.kept.size(); ++k) {
    EXPECT_EQ(selection.kept[k] - selection.kept[k - 1], selection.kept[1]) << k;
  }
}

TEST(FrameSelectionTest, NoSpacingKeepsEveryFrameAndBadOptionsAreRefused) {
  FrameSelectionOptions options;
  options.min_distance_m = 0;
  options.min_rotation_deg = 0;
  options.max_frames = 0;
  EXPECT_EQ(SelectFrames(DriveWithStop(12, 1, 3, 8), options).kept.size(), 12u);
  options.max_frames = 5;  // a cap with no spacing to grow
  EXPECT_THROW(SelectFrames({}, options), std::invalid_argument);
  options = FrameSelectionOptions();
  options.max_frames = 1;
  EXPECT_THROW(SelectFrames({}, options), std::invalid_argument);
  options = FrameSelectionOptions();
  options.min_distance_m = -1;
  EXPECT_THROW(SelectFrames({}, options), std::invalid_argument);
  EXPECT_TRUE(SelectFrames({}, FrameSelectionOptions()).kept.empty());
}

}  // namespace
}  // namespace colmap_lidar
