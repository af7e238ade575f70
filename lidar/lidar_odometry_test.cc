#include "lidar/lidar_odometry.h"

#include "lidar/trajectory_error.h"
#include "tests/testing/ray_cast_street.h"

#include <gtest/gtest.h>
#include <omp.h>

namespace colmap_lidar {
namespace {

constexpr double kPeriod = 0.1;  // 10 Hz sweeps

struct Drive {
  std::vector<std::vector<Eigen::Vector3d>> sweeps;
  std::vector<Eigen::Isometry3d> truth;  // world_from_lidar at each sweep's middle
};

// `n` raw sweeps of a car at `speed` m/s down the ray-cast street.
Drive SimulateDrive(int n, double speed, bool walls_only = false, uint32_t seed = 1) {
  const std::vector<testing::Box> boxes =
      testing::StreetBoxes(seed, speed * kPeriod * n, walls_only);
  std::mt19937 rng(seed);
  Drive drive;
  for (int k = 0; k < n; ++k) {
    drive.sweeps.push_back(
        testing::ScanSweep(boxes, k * kPeriod, kPeriod, speed, 32, 720, 0.02, &rng));
    drive.truth.push_back(testing::DrivePose(k * kPeriod, speed));
  }
  return drive;
}

std::vector<Eigen::Isometry3d> RunOdometry(const Drive& drive,
                                           const LidarOdometryOptions& options) {
  LidarOdometry odometry(options);
  std::vector<Eigen::Isometry3d> poses;
  for (size_t k = 0; k < drive.sweeps.size(); ++k) {
    poses.push_back(
        odometry.RegisterFrame(drive.sweeps[k], static_cast<double>(k)).world_from_lidar);
  }
  return poses;
}

LidarOdometryOptions StreetOptions() {
  LidarOdometryOptions options;
  options.max_range_m = 60;  // voxels of 0.6 m for the synthetic street
  return options;
}

TEST(LidarOdometry, FollowsARawDrive) {
  const Drive drive = SimulateDrive(60, 12.0);
  TrajectoryErrorOptions metric;
  metric.lengths_m = {10, 20, 40};
  const TrajectoryError deskewed =
      EvaluateTrajectoryError(RunOdometry(drive, StreetOptions()), drive.truth, metric);
  LidarOdometryOptions raw = StreetOptions();
  raw.deskew = false;
  const TrajectoryError skewed =
      EvaluateTrajectoryError(RunOdometry(drive, raw), drive.truth, metric);
  std::cout << "odometry on the raw street drive: de-skewed " << deskewed.translation_percent
            << " % / " << deskewed.rotation_deg_per_m << " deg/m, without de-skewing "
            << skewed.translation_percent << " % / " << skewed.rotation_deg_per_m << " deg/m"
            << std::endl;
  // Measured 0.12 % / 0.0068 deg/m: bounds about 3x.
  EXPECT_LT(deskewed.translation_percent, 0.4);
  EXPECT_LT(deskewed.rotation_deg_per_m, 0.02);
  EXPECT_LT(deskewed.translation_percent, skewed.translation_percent);
}

// Sweeps that carry per-point times are de-skewed by them: with a wrong start azimuth in the
// options, the timed sweeps follow the drive as well as correctly timed ones, the untimed do not.
TEST(LidarOdometry, PerPointTimesDeskewWhateverTheAzimuthOptions) {
  const Drive drive = SimulateDrive(30, 12.0);
  LidarOdometryOptions wrong = StreetOptions();
  wrong.timing.start_azimuth_deg = 0;
  LidarOdometry timed(wrong), untimed(wrong), right(StreetOptions());
  std::vector<Eigen::Isometry3d> timed_poses, untimed_poses, right_poses;
  for (size_t k = 0; k < drive.sweeps.size(); ++k) {
    PointCloud sweep;
    sweep.points = drive.sweeps[k];
    for (const Eigen::Vector3d& point : sweep.points) {
      sweep.times.push_back(5.0 + kPeriod * k + kPeriod * SweepFraction(point, {}));
    }
    timed_poses.push_back(timed.RegisterFrame(sweep, static_cast<double>(k)).world_from_lidar);
    untimed_poses.push_back(
        untimed.RegisterFrame(drive.sweeps[k], static_cast<double>(k)).world_from_lidar);
    right_poses.push_back(
        right.RegisterFrame(drive.sweeps[k], static_cast<double>(k)).world_from_lidar);
  }
  TrajectoryErrorOptions metric;
  metric.lengths_m = {10, 20};
  const double with_times =
      EvaluateTrajectoryError(timed_poses, drive.truth, metric).translation_percent;
  const double without =
      EvaluateTrajectoryError(untimed_poses, drive.truth, metric).translation_percent;
  const double correct =
      EvaluateTrajectoryError(right_poses, drive.truth, metric).translation_percent;
  std::cout << "wrong start azimuth: timed " << with_times << " %, untimed " << without
            << " %; right azimuth " << correct << " %" << std::endl;
  // Measured 0.0920 % and 0.0927 % timed and right, 0.157 % untimed.
  EXPECT_NEAR(with_times, correct, 0.003);
  EXPECT_GT(without, 1.3 * with_times);
}

TEST(LidarOdometry, NamesTheDegenerateDirectionOfAStreetOfBareWalls) {
  const Drive drive = SimulateDrive(12, 10.0, /*walls_only=*/true);
  LidarOdometry odometry(StreetOptions());
  int along_the_street = 0;
  for (size_t k = 0; k < drive.sweeps.size(); ++k) {
    const OdometryFrame& frame = odometry.RegisterFrame(drive.sweeps[k], static_cast<double>(k));
    std::cout << "frame " << k << ": degenerate " << frame.degenerate << ", ratio "
              << frame.constraints.weakest_ratio << ", weakest "
              << frame.constraints.WeakestAxisName() << ", x "
              << frame.world_from_lidar.translation().x() << std::endl;
    if (k == 0 || !frame.degenerate) continue;
    EXPECT_FALSE(frame.covariance.has_value()) << k;
    // The weakest direction: the translation along the street (x).
    if (frame.constraints.WeakestAxisName() == "tx") ++along_the_street;
  }
  // At least the first frames, before the map holds the few returns that vary along the walls.
  EXPECT_GE(along_the_street, 2);
  // The real street is not degenerate.
  const Drive street = SimulateDrive(6, 10.0);
  LidarOdometry normal(StreetOptions());
  for (size_t k = 0; k < street.sweeps.size(); ++k) {
    const OdometryFrame& frame = normal.RegisterFrame(street.sweeps[k], static_cast<double>(k));
    if (k > 0) {
      EXPECT_FALSE(frame.degenerate) << k << " " << frame.constraints.weakest_ratio;
      ASSERT_TRUE(frame.covariance.has_value());
      EXPECT_GT(frame.covariance->diagonal().minCoeff(), 0);
    }
  }
}

// The odometry's sums are combined in a fixed order.
TEST(LidarOdometry, GivesTheSamePosesOnOneAndFourThreads) {
  const Drive drive = SimulateDrive(8, 12.0);
  const LidarOdometryOptions options = StreetOptions();
  omp_set_num_threads(1);
  const auto one = RunOdometry(drive, options);
  omp_set_num_threads(4);
  const auto four = RunOdometry(drive, options);
  for (size_t k = 0; k < one.size(); ++k) {
    EXPECT_TRUE(one[k].matrix() == four[k].matrix()) << k;
  }
}

TEST(LidarOdometry, RefusesAnEmptyFrameAndATimeGoingBack) {
  LidarOdometry odometry(StreetOptions());
  EXPECT_THROW(odometry.RegisterFrame({Eigen::Vector3d(0.1, 0, 0)}, 0), std::runtime_error);
  const Drive drive = SimulateDrive(2, 10.0);
  odometry.RegisterFrame(drive.sweeps[0], 0);
  EXPECT_THROW(odometry.RegisterFrame(drive.sweeps[1], 0), std::invalid_argument);
  LidarOdometryOptions bad;
  bad.min_range_m = 200;
  EXPECT_THROW(LidarOdometry{bad}, std::invalid_argument);
}

// The first motion, which nothing predicts, from rest at 1.6 and 2 m per sweep (58 and 72 km/h
// at 10 Hz) on twelve streets. With the narrow kernel alone the ICP stops near rest on 4 of the
// 24 (measured); with the graduated kernel on 1 (a street whose first sweeps see little but walls).
TEST(LidarOdometry, FindsAFastFirstMotionFromRest) {
  int missed = 0;
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    for (const double speed : {16.0, 20.0}) {
      const std::vector<testing::Box> boxes = testing::StreetBoxes(seed, 2 * speed * kPeriod + 40);
      std::mt19937 rng(seed);
      LidarOdometry odometry(StreetOptions());
      for (int k = 0; k < 2; ++k) {
        const OdometryFrame& frame = odometry.RegisterFrame(
            testing::ScanSweep(boxes, k * kPeriod, kPeriod, speed, 64, 1800, 0.01, &rng, 2, -24.8),
            k);
        if (k == 0) continue;
        const Eigen::Isometry3d truth =
            testing::DrivePose(0, speed).inverse() * testing::DrivePose(kPeriod, speed);
        const double error = (frame.world_from_lidar.translation() - truth.translation()).norm();
        if (error > 0.1) {
          ++missed;
          std::cout << "street " << seed << " at " << speed << " m/s: first motion " << error
                    << " m off" << std::endl;
        }
      }
    }
  }
  EXPECT_LE(missed, 1);
}

}  // namespace
}  // namespace colmap_lidar
