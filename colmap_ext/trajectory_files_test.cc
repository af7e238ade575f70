#include "colmap_ext/trajectory_files.h"

#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>

#include <fstream>

namespace colmap_lidar {
namespace {

colmap::Rigid3d GenericPose(double k) {
  return colmap::Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(
                             0.1 + 0.2 * k, Eigen::Vector3d(0.3, -0.5, 0.8).normalized())),
                         Eigen::Vector3d(1.5 * k, -0.25 * k, 0.1 + k));
}

void Write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

// The message of the std::runtime_error `call` throws ("" if none).
template <typename Call>
std::string ErrorOf(Call call) {
  try {
    call();
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

TEST(TrajectoryFiles, KittiAndTumRoundTripAndAreDetected) {
  testing::ScopedTempDir dir("colmap_lidar_trajectory_files");
  Trajectory trajectory;
  for (int k = 0; k < 4; ++k) {
    trajectory.names.push_back("00000" + std::to_string(k));
    trajectory.world_from_sensor.push_back(GenericPose(k));
  }
  WriteTrajectoryExports(dir.File("poses"), trajectory);
  EXPECT_EQ(DetectTrajectoryFileFormat(dir.File("poses_kitti.txt")), TrajectoryFileFormat::kKitti);
  EXPECT_EQ(DetectTrajectoryFileFormat(dir.File("poses_tum.txt")), TrajectoryFileFormat::kTum);
  const Trajectory kitti =
      ReadTrajectoryFile(dir.File("poses_kitti.txt"), TrajectoryFileFormat::kKitti);
  const Trajectory tum = ReadTumTrajectory(dir.File("poses_tum.txt"));
  ASSERT_EQ(kitti.Size(), 4u);
  ASSERT_EQ(tum.Size(), 4u);
  EXPECT_EQ(kitti.names[3], "3");
  EXPECT_EQ(tum.times, (std::vector<double>{0, 1, 2, 3}));  // numeric names as times
  for (int k = 0; k < 4; ++k) {
    const colmap::Rigid3d& truth = trajectory.world_from_sensor[k];
    for (const Trajectory* read : {&kitti, &tum}) {
      EXPECT_LT(read->world_from_sensor[k].rotation.angularDistance(truth.rotation), 1e-8);
      EXPECT_LT((read->world_from_sensor[k].translation - truth.translation).norm(), 1e-8);
    }
  }
}

TEST(TrajectoryFiles, NamedFilesTakeTheirDirectionFromTheName) {
  testing::ScopedTempDir dir("colmap_lidar_trajectory_files");
  Write(dir.File("cam_from_world.txt"), "# c\na 1 0 0 0 1 2 3\n");
  Write(dir.File("lidar_poses.txt"), "a 1 0 0 0 1 2 3\n");
  EXPECT_EQ(DetectTrajectoryFileFormat(dir.File("cam_from_world.txt")),
            TrajectoryFileFormat::kNamedSensorFromWorld);
  EXPECT_EQ(DetectTrajectoryFileFormat(dir.File("lidar_poses.txt")),
            TrajectoryFileFormat::kNamedWorldFromSensor);
  const Trajectory inverted = ReadTrajectoryFile(dir.File("cam_from_world.txt"),
                                                 TrajectoryFileFormat::kNamedSensorFromWorld);
  EXPECT_TRUE(inverted.world_from_sensor[0].translation.isApprox(Eigen::Vector3d(-1, -2, -3)));
  EXPECT_EQ(TrajectoryFileFormatFromName("tum"), TrajectoryFileFormat::kTum);
  EXPECT_THROW(TrajectoryFileFormatFromName("euroc"), std::invalid_argument);
}

TEST(TrajectoryFiles, BadFilesNameTheFileAndLine) {
  testing::ScopedTempDir dir("colmap_lidar_trajectory_files");
  const std::string kitti = dir.File("poses.txt");
  Write(kitti, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  EXPECT_EQ(ReadKittiPoses(kitti, 2).size(), 2u);
  EXPECT_EQ(ErrorOf([&] { ReadKittiPoses(kitti, 3); }),
            kitti + ":2: the file ends after 2 poses, but frame 2 needs one");
  Write(kitti, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 nan 0 1 0 0 0 0 1 0\n");
  EXPECT_EQ(ErrorOf([&] { ReadKittiPoses(kitti); }), kitti + ":2: 'nan' is not a finite number");
  Write(kitti, "1 0 0 0 0 1 0 0 0 0 1\n");
  EXPECT_EQ(ErrorOf([&] { ReadKittiPoses(kitti); }), kitti + ":1: 11 values where 12 are expected");
  Write(kitti, "2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_EQ(ErrorOf([&] { ReadKittiPoses(kitti); }), kitti + ":1: the 3x3 block is not a rotation");
  const std::string times = dir.File("times.txt");
  Write(times, "0.0\n0.1\n0.1\n");
  EXPECT_EQ(ErrorOf([&] { ReadKittiTimes(times); }),
            times + ":3: time 0.100000000 is not after the one before");
  const std::string tum = dir.File("tum.txt");
  Write(tum, "# t x y z qx qy qz qw\n1.0 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n");
  EXPECT_EQ(ErrorOf([&] { ReadTumTrajectory(tum); }),
            tum + ":3: timestamp 0.500000000 is not after the one before");
  EXPECT_NE(ErrorOf([&] { DetectTrajectoryFileFormat(dir.File("missing.txt")); }), "");
}

}  // namespace
}  // namespace colmap_lidar
