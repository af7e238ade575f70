#include "lidar/sweep_deskew.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace colmap_lidar {
namespace {

Eigen::Isometry3d Motion(double yaw_deg, const Eigen::Vector3d& translation) {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() =
      Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d(0.05, 0.1, 1).normalized())
          .toRotationMatrix();
  motion.translation() = translation;
  return motion;
}

// A car speeding up and turning: the previous sweep's middle 0.8 m behind (2 deg of yaw), the next one
// 1 m ahead (3 deg).
SweepMotion CarMotion() {
  SweepMotion motion;
  motion.mid_from_previous_mid = Motion(-2, Eigen::Vector3d(-0.8, -0.05, 0.0));
  motion.mid_from_next_mid = Motion(3, Eigen::Vector3d(1.0, 0.08, 0.01));
  return motion;
}

// The LiDAR's pose at `fraction` of the sweep, in the frame of the sweep's middle: uniform motion
// within each half, from halfway to the previous middle to halfway to the next.
Eigen::Isometry3d MidFromLidarAt(double fraction) {
  const double s = fraction - 0.5;
  const Eigen::Isometry3d& neighbour =
      s < 0 ? CarMotion().mid_from_previous_mid : CarMotion().mid_from_next_mid;
  const Eigen::AngleAxisd rotation(neighbour.rotation());
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      Eigen::AngleAxisd(std::abs(s) * rotation.angle(), rotation.axis()).toRotationMatrix();
  pose.translation() = std::abs(s) * neighbour.translation();
  return pose;
}

// A sweep of points on walls 4-20 m around, each measured at the fraction of its azimuth in the
// moving LiDAR frame; returns the sweep and the same points in the mid frame.
void MakeSweep(PointCloud* sweep, std::vector<Eigen::Vector3d>* points_in_mid) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int k = 0; k < 20000; ++k) {
    const double fraction = unit(rng);
    const double azimuth = M_PI + 2 * M_PI * fraction;  // starts behind, counter-clockwise
    const double range = 4 + 16 * unit(rng);
    const Eigen::Vector3d point_in_lidar(
        range * std::cos(azimuth), range * std::sin(azimuth), -1.5 + 3 * unit(rng));
    sweep->points.push_back(point_in_lidar);
    points_in_mid->push_back(MidFromLidarAt(fraction) * point_in_lidar);
  }
}

TEST(SweepDeskew, FractionFollowsTheAzimuthFromTheStart) {
  const SweepTimingOptions options;
  EXPECT_NEAR(SweepFraction(Eigen::Vector3d(-1, -1e-9, 0), options), 0.0, 1e-6);
  EXPECT_NEAR(SweepFraction(Eigen::Vector3d(0, -1, 0), options), 0.25, 1e-12);
  EXPECT_NEAR(SweepFraction(Eigen::Vector3d(1, 0, 0), options), 0.5, 1e-12);
  EXPECT_NEAR(SweepFraction(Eigen::Vector3d(0, 1, 0), options), 0.75, 1e-12);
  SweepTimingOptions clockwise;
  clockwise.counter_clockwise = false;
  EXPECT_NEAR(SweepFraction(Eigen::Vector3d(0, 1, 0), clockwise), 0.25, 1e-12);
}

// The de-skewed points are where they were at the middle of the sweep, to floating-point precision (the
// motion is exactly the model undone, each half with its own neighbour); the raw sweep is smeared by up
// to half the motion per sweep.
TEST(SweepDeskew, UndoesTheMotionOfEachHalfSweep) {
  PointCloud sweep;
  std::vector<Eigen::Vector3d> truth;
  MakeSweep(&sweep, &truth);
  sweep.intensities.assign(sweep.Size(), 7.f);
  const PointCloud deskewed = DeskewSweep(sweep, CarMotion(), SweepTimingOptions());
  ASSERT_EQ(deskewed.Size(), sweep.Size());
  EXPECT_EQ(deskewed.intensities, sweep.intensities);
  double worst_raw = 0, worst_deskewed = 0;
  for (size_t i = 0; i < sweep.Size(); ++i) {
    worst_raw = std::max(worst_raw, (sweep.points[i] - truth[i]).norm());
    worst_deskewed = std::max(worst_deskewed, (deskewed.points[i] - truth[i]).norm());
  }
  EXPECT_GT(worst_raw, 0.5);
  EXPECT_LT(worst_deskewed, 1e-9);
  // Without motion nothing moves.
  const PointCloud still = DeskewSweep(sweep, SweepMotion(), SweepTimingOptions());
  EXPECT_EQ(still.points, sweep.points);
}

// A driver's per-point times (absolute seconds here) time the sweep, whatever the azimuth options
// say: with a wrong start azimuth the azimuth's fractions are wrong, the times' are not.
TEST(SweepDeskew, PerPointTimesTimeTheSweepWhateverTheAzimuth) {
  PointCloud sweep;
  std::vector<Eigen::Vector3d> truth;
  MakeSweep(&sweep, &truth);
  for (const Eigen::Vector3d& point : sweep.points) {
    const double fraction = SweepFraction(point, SweepTimingOptions());
    sweep.times.push_back(1.3e9 + 0.1 * fraction);
  }
  SweepTimingOptions wrong;
  wrong.start_azimuth_deg = 0;
  double worst_timed = 0, worst_by_azimuth = 0;
  const PointCloud timed = DeskewSweep(sweep, CarMotion(), wrong);
  PointCloud untimed = sweep;
  untimed.times.clear();
  const PointCloud by_azimuth = DeskewSweep(untimed, CarMotion(), wrong);
  EXPECT_FALSE(timed.HasTimes());
  for (size_t i = 0; i < sweep.Size(); ++i) {
    worst_timed = std::max(worst_timed, (timed.points[i] - truth[i]).norm());
    worst_by_azimuth = std::max(worst_by_azimuth, (by_azimuth.points[i] - truth[i]).norm());
  }
  std::cout << "worst error: timed " << worst_timed << " m, by the wrong azimuth "
            << worst_by_azimuth << " m" << std::endl;
  // Measured 1.5e-5 m: the earliest and latest points are about a 20000th of the sweep from its
  // ends.
  EXPECT_LT(worst_timed, 5e-5);
  EXPECT_GT(worst_by_azimuth, 0.3);
}

TEST(SweepDeskew, RefusesTimesThatDoNotTimeTheSweep) {
  PointCloud sweep;
  std::vector<Eigen::Vector3d> truth;
  MakeSweep(&sweep, &truth);
  sweep.times.assign(sweep.Size(), 0.0);  // a driver that writes zeros
  EXPECT_THROW(SweepFractions(sweep, SweepTimingOptions()), std::invalid_argument);
  for (size_t i = 0; i < sweep.Size(); ++i) sweep.times[i] = 0.1 * i / sweep.Size();
  EXPECT_NO_THROW(SweepFractions(sweep, SweepTimingOptions()));
  sweep.times[17] = 1e6;  // one time far from the sweep's
  EXPECT_THROW(SweepFractions(sweep, SweepTimingOptions()), std::invalid_argument);
  sweep.times.pop_back();
  EXPECT_THROW(SweepFractions(sweep, SweepTimingOptions()), std::invalid_argument);
}

// Poses of four sweeps at frames 10, 11, 13 (one frame skipped) and 14, the last in another
// component: motions per frame, the skipped frame halving the motion, mirrored at the ends.
TEST(SweepDeskew, MotionsFromPosesArePerFrameAndMirroredAtTheEnds) {
  const Eigen::Isometry3d step = Motion(2, Eigen::Vector3d(0.9, 0.04, 0.0));
  std::vector<Eigen::Isometry3d> world_from_lidar = {
      Eigen::Isometry3d::Identity(), step, step * step * step, Motion(40, {5, 5, 0})};
  const std::vector<SweepMotion> motions =
      SweepMotionsFromPoses(world_from_lidar, {10, 11, 13, 14}, {0, 0, 0, 1});
  ASSERT_EQ(motions.size(), 4u);
  auto near = [](const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    return (a.matrix() - b.matrix()).norm() < 1e-9;
  };
  EXPECT_TRUE(near(motions[0].mid_from_next_mid, step));
  EXPECT_TRUE(near(motions[0].mid_from_previous_mid, step.inverse()));  // mirrored
  EXPECT_TRUE(near(motions[1].mid_from_previous_mid, step.inverse()));
  // Two frames of `step`, per frame: half the angle about the same axis, half the translation.
  auto halved = [](const Eigen::Isometry3d& motion) {
    const Eigen::AngleAxisd rotation(motion.rotation());
    Eigen::Isometry3d half = Eigen::Isometry3d::Identity();
    half.linear() = Eigen::AngleAxisd(0.5 * rotation.angle(), rotation.axis()).toRotationMatrix();
    half.translation() = 0.5 * motion.translation();
    return half;
  };
  EXPECT_TRUE(near(motions[1].mid_from_next_mid, halved(step * step)));
  EXPECT_TRUE(near(motions[2].mid_from_previous_mid, halved((step * step).inverse())));
  // The next sweep is not comparable: the previous motion mirrored.
  EXPECT_TRUE(near(motions[2].mid_from_next_mid, halved((step * step).inverse()).inverse()));
  EXPECT_TRUE(near(motions[3].mid_from_next_mid, Eigen::Isometry3d::Identity()));
  EXPECT_THROW(SweepMotionsFromPoses(world_from_lidar, {1, 2}, {0, 0, 0, 0}),
               std::invalid_argument);
}

TEST(SweepClock, FollowsTheTimestampsAcrossADroppedFrame) {
  // Sweeps of 0.1 s, frame 2 dropped by the driver: the third sweep's middle is 3 sweeps after the
  // first, so SweepMotionsFromPoses divides its motion by 3.
  const std::vector<std::pair<double, double>> times = {
      {100.00, 100.10}, {100.10, 100.20}, {100.30, 100.40}, {100.40, 100.5004}};
  const std::vector<double> clock = SweepClockFromTimes(times);
  ASSERT_EQ(clock.size(), 4u);
  EXPECT_NEAR(clock[0], 0.0, 1e-9);
  EXPECT_NEAR(clock[1], 1.0, 1e-6);
  EXPECT_NEAR(clock[2], 3.0, 1e-6);
  EXPECT_NEAR(clock[3], 4.002, 1e-6);
  EXPECT_THROW(SweepClockFromTimes({{1.0, 1.0}}), std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
