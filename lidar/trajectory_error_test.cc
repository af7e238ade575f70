#include "lidar/trajectory_error.h"

#include <gtest/gtest.h>

#include <cmath>

namespace colmap_lidar {
namespace {

using Poses = std::vector<Eigen::Isometry3d>;

Eigen::Isometry3d Pose(double yaw_rad, const Eigen::Vector3d& position) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = position;
  return pose;
}

// A car driving 1 m per frame along x with a gentle weave, `n` frames (a LiDAR frame: z up).
Poses Drive(int n) {
  Poses poses;
  for (int k = 0; k < n; ++k) {
    const double y = 0.5 * std::sin(0.05 * k);
    const double heading = std::atan(0.5 * 0.05 * std::cos(0.05 * k));
    poses.push_back(Pose(heading, Eigen::Vector3d(k, y, 0.02 * std::sin(0.3 * k))));
  }
  return poses;
}

// The drive's motions recomposed with each step's translation scaled by `scale` and a yaw of
// `yaw_deg_per_m` per metre of the step added: a scale error and a constant heading drift.
Poses Distorted(const Poses& truth, double scale, double yaw_deg_per_m) {
  Poses out = {truth.front()};
  for (size_t k = 1; k < truth.size(); ++k) {
    Eigen::Isometry3d step = truth[k - 1].inverse() * truth[k];
    const double length = step.translation().norm();
    step.translation() *= scale;
    step.linear() = Eigen::AngleAxisd(yaw_deg_per_m * length * M_PI / 180, Eigen::Vector3d::UnitZ())
                        .toRotationMatrix() *
                    step.linear();
    out.push_back(out.back() * step);
  }
  return out;
}

TEST(TrajectoryError, IdenticalTrajectoriesHaveNoError) {
  const Poses drive = Drive(120);
  const TrajectoryError error = EvaluateTrajectoryError(drive, drive, TrajectoryErrorOptions());
  EXPECT_EQ(error.num_poses, 120u);
  EXPECT_NEAR(error.path_length_m, 119.0, 0.5);
  ASSERT_EQ(error.lengths.size(), 11u);  // 10 .. 110 m
  EXPECT_GT(error.num_segments, 0);
  EXPECT_NEAR(error.translation_percent, 0, 1e-9);
  EXPECT_NEAR(error.rotation_deg_per_m, 0, 1e-9);
  EXPECT_NEAR(error.position_rmse_m, 0, 1e-9);
  EXPECT_EQ(error.steps.size(), 119u);
}

TEST(TrajectoryError, AOnePercentScaleErrorReadsOnePercent) {
  const Poses truth = Drive(120);
  const TrajectoryError error =
      EvaluateTrajectoryError(Distorted(truth, 1.01, 0), truth, TrajectoryErrorOptions());
  // |t(E)| = 0.01 of the chord, a hair shorter than the weaving path's length.
  EXPECT_NEAR(error.translation_percent, 1.0, 0.01);
  EXPECT_NEAR(error.rotation_deg_per_m, 0, 1e-9);
  for (const SegmentLengthError& length : error.lengths) {
    EXPECT_NEAR(length.translation_percent, 1.0, 0.01) << length.length_m;
  }
  EXPECT_NEAR(error.end_to_end_drift_percent, 1.0, 0.01);
  // A similarity alignment takes the scale out.
  TrajectoryErrorOptions similarity;
  similarity.alignment = TrajectoryAlignment::kSimilarity;
  const TrajectoryError aligned =
      EvaluateTrajectoryError(Distorted(truth, 1.01, 0), truth, similarity);
  EXPECT_NEAR(aligned.alignment_scale, 1 / 1.01, 1e-9);
  EXPECT_NEAR(aligned.translation_percent, 0, 1e-6);
  EXPECT_NEAR(aligned.position_rmse_m, 0, 1e-6);
}

TEST(TrajectoryError, AConstantYawDriftReadsInDegreesPerMetre) {
  const Poses truth = Drive(120);
  const TrajectoryError error =
      EvaluateTrajectoryError(Distorted(truth, 1.0, 0.01), truth, TrajectoryErrorOptions());
  EXPECT_NEAR(error.rotation_deg_per_m, 0.01, 1e-4);
  for (const StepError& step : error.steps) {
    EXPECT_NEAR(step.rotation_error_deg, 0.01 * step.length_m, 1e-9);
  }
  // The heading drift bends the path: on a segment of L metres the end is off by about
  // L * angle / 2, i.e. 0.0087 % per metre of segment length.
  EXPECT_GT(error.translation_percent, 0.01);
  EXPECT_LT(error.translation_percent, 0.6);
}

TEST(TrajectoryError, RefusesMismatchedTrajectories) {
  const Poses drive = Drive(10);
  EXPECT_THROW(EvaluateTrajectoryError(
                   drive, Poses(drive.begin(), drive.end() - 1), TrajectoryErrorOptions()),
               std::invalid_argument);
  EXPECT_THROW(
      EvaluateTrajectoryError(Poses(1, drive[0]), Poses(1, drive[0]), TrajectoryErrorOptions()),
      std::invalid_argument);
  TrajectoryErrorOptions bad;
  bad.lengths_m = {10, -1};
  EXPECT_THROW(EvaluateTrajectoryError(drive, drive, bad), std::invalid_argument);
}

TEST(TrajectoryError, APathShorterThanEveryLengthHasStepsAndAbsoluteErrorsOnly) {
  const Poses drive = Drive(5);
  const TrajectoryError error =
      EvaluateTrajectoryError(Distorted(drive, 1.02, 0), drive, TrajectoryErrorOptions());
  EXPECT_TRUE(error.lengths.empty());
  EXPECT_EQ(error.num_segments, 0);
  EXPECT_EQ(error.steps.size(), 4u);
  EXPECT_NEAR(error.steps[0].translation_error_m, 0.02 * error.steps[0].length_m, 1e-9);
  EXPECT_GT(error.position_rmse_m, 0);
}

}  // namespace
}  // namespace colmap_lidar
