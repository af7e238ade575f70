// OXTS packets and timestamps against values computed by hand from the development kit's
// convention (no shared raw sample carries OXTS).
#include "colmap_ext/kitti_oxts.h"

#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace colmap_lidar {
namespace {

constexpr double kLatitude = 49.0, kLongitude = 8.4, kRadius = 6378137.0;

std::string PacketLine(double lat, double lon, double alt, double roll, double pitch, double yaw) {
  std::ostringstream line;
  line << std::setprecision(17) << lat << " " << lon << " " << alt << " " << roll << " " << pitch
       << " " << yaw;
  for (int k = 6; k < 30; ++k) line << " " << 0.01 * k;  // velocities, accuracies, ...: unused
  return line.str() + "\n";
}

OxtsPacket Packet(const testing::ScopedTempDir& dir, const std::string& line) {
  const std::string path = dir.File("packet.txt");
  std::ofstream(path) << line;
  return ReadOxtsPacket(path);
}

Eigen::Matrix3d Rzyx(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

TEST(KittiOxts, PacketsBecomePosesInTheFirstPacketsImuFrame) {
  testing::ScopedTempDir dir("colmap_lidar_oxts");
  // The car faces north (yaw 90 deg) at the first packet; then 10 m east and 1 m up, turned 0.1 rad
  // further; then 20 m north (r * dlat: the Mercator y grows by dlat / cos(lat) times s = cos(lat)),
  // rolled and pitched.
  const double east_deg = 10.0 / (std::cos(kLatitude * M_PI / 180) * kRadius) * 180 / M_PI;
  const double north_deg = 20.0 / kRadius * 180 / M_PI;
  const std::vector<OxtsPacket> packets = {
      Packet(dir, PacketLine(kLatitude, kLongitude, 110, 0, 0, M_PI / 2)),
      Packet(dir, PacketLine(kLatitude, kLongitude + east_deg, 111, 0, 0, M_PI / 2 + 0.1)),
      Packet(dir, PacketLine(kLatitude + north_deg, kLongitude, 110, 0.2, -0.1, 0.3))};
  const std::vector<colmap::Rigid3d> poses = WorldFromImuFromOxts(packets);
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_LT(poses[0].translation.norm(), 1e-9);
  EXPECT_LT(poses[0].rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-12);
  // East is the first IMU frame's -y (it faces north: x north, y west).
  EXPECT_LT((poses[1].translation - Eigen::Vector3d(0, -10, 1)).norm(), 1e-6);
  EXPECT_TRUE(poses[1].rotation.toRotationMatrix().isApprox(Rzyx(0.1, 0, 0), 1e-12));
  // North is its +x; the second-order Mercator term is 0.5 tan(lat) dlat 20 m = 4e-5 m.
  EXPECT_LT((poses[2].translation - Eigen::Vector3d(20, 0, 0)).norm(), 1e-4);
  EXPECT_TRUE(poses[2].rotation.toRotationMatrix().isApprox(
      Rzyx(M_PI / 2, 0, 0).transpose() * Rzyx(0.3, -0.1, 0.2), 1e-12));
}

TEST(KittiOxts, BadPacketsNameTheFileAndLine) {
  testing::ScopedTempDir dir("colmap_lidar_oxts");
  const std::string path = dir.File("packet.txt");
  std::ofstream(path) << "49.0 8.4 nan 0 0 0" << std::string(24 * 2, ' ') << "\n";
  try {
    ReadOxtsPacket(path);
    FAIL() << "a NaN altitude was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_EQ(std::string(error.what()), path + ":1: 'nan' is not a finite number");
  }
  std::ofstream(path) << "49.0 8.4 100 0 0 0\n";
  EXPECT_THROW(ReadOxtsPacket(path), std::runtime_error);  // 6 of 30 values
  EXPECT_THROW(ReadOxtsPacket(dir.File("missing.txt")), std::runtime_error);
}

TEST(KittiOxts, TimestampsAreSecondsSinceTheEpoch) {
  testing::ScopedTempDir dir("colmap_lidar_oxts");
  const std::string path = dir.File("timestamps.txt");
  std::ofstream(path) << "2011-09-26 13:02:25.594360375\n2012-02-29 00:00:00.000000000\n";
  const std::vector<double> times = ReadKittiTimestamps(path, 2);
  ASSERT_EQ(times.size(), 2u);
  EXPECT_NEAR(times[0], 1317042145.594360375, 1e-6);
  EXPECT_NEAR(times[1], 1330473600.0, 1e-6);
  try {
    ReadKittiTimestamps(path, 3);
    FAIL() << "two timestamps served three frames";
  } catch (const std::runtime_error& error) {
    EXPECT_EQ(std::string(error.what()),
              path + ":2: the file ends after 2 timestamps, but frame 2 needs one");
  }
  std::ofstream(path) << "2011-09-26 13:02:25.5\n2011-09-26 13:02:25.4\n";
  try {
    ReadKittiTimestamps(path);
    FAIL() << "timestamps out of order were accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_EQ(std::string(error.what()),
              path + ":2: timestamp 2011-09-26 13:02:25.4 is not after the one before");
  }
  std::ofstream(path) << "2011-13-26 13:02:25.5\n";
  EXPECT_THROW(ReadKittiTimestamps(path), std::runtime_error);
}

}  // namespace
}  // namespace colmap_lidar
