#include "bridge/pipeline/capture_profile.h"

#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>

#include <fstream>

namespace colmap_lidar {
namespace {

StationDataset DatasetWith(bool stereo, bool moving) {
  StationDataset dataset;
  dataset.rig.left = colmap::Camera::CreateFromModelName(1, "PINHOLE", 500, 640, 480);
  if (stereo) dataset.rig.right = dataset.rig.left;
  dataset.rig.moving_platform = moving;
  return dataset;
}

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(CaptureProfileTest, DecidedFromTheRigAndTheHandEyesAxis) {
  const CaptureProfile tripod = DecideCaptureProfile(DatasetWith(true, false), std::nullopt);
  EXPECT_EQ(tripod.rig, CameraRig::kStereo);
  EXPECT_EQ(tripod.platform, Platform::kStations);
  EXPECT_EQ(tripod.rotation, StationRotation::kTwoAxes);
  EXPECT_FALSE(tripod.IsMovingPlatform());
  const CaptureProfile drive =
      DecideCaptureProfile(DatasetWith(false, false), Eigen::Vector3d(0, -2, 0));
  EXPECT_EQ(drive.rig, CameraRig::kMonocular);
  EXPECT_EQ(drive.rotation, StationRotation::kOneAxis);
  EXPECT_TRUE(drive.IsMovingPlatform());  // rotations about one axis: a platform that drives
  EXPECT_TRUE(drive.one_axis_in_cam->isApprox(Eigen::Vector3d(0, -1, 0)));
  EXPECT_TRUE(DecideCaptureProfile(DatasetWith(true, true), std::nullopt).IsMovingPlatform());
}

TEST(CaptureProfileTest, RoundTripsThroughItsFile) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File(kCaptureProfileFile);
  const CaptureProfile written =
      DecideCaptureProfile(DatasetWith(false, true), Eigen::Vector3d(0.1, -1, 0.05));
  WriteCaptureProfile(path, written);
  const CaptureProfile read = ReadCaptureProfile(path);
  EXPECT_EQ(read.rig, written.rig);
  EXPECT_EQ(read.platform, written.platform);
  EXPECT_EQ(read.rotation, written.rotation);
  ASSERT_TRUE(read.one_axis_in_cam.has_value());
  EXPECT_LT((*read.one_axis_in_cam - *written.one_axis_in_cam).norm(), 1e-12);
  const CaptureProfile tripod = DecideCaptureProfile(DatasetWith(true, false), std::nullopt);
  WriteCaptureProfile(path, tripod);
  EXPECT_FALSE(ReadCaptureProfile(path).one_axis_in_cam.has_value());
}

TEST(CaptureProfileTest, AMalformedFileIsAnErrorNamingIt) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File(kCaptureProfileFile);
  const auto expect_error = [&path](const std::string& text, const std::string& says) {
    WriteText(path, text);
    try {
      ReadCaptureProfile(path);
      ADD_FAILURE() << "no error for " << text;
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
      EXPECT_NE(std::string(error.what()).find(says), std::string::npos) << error.what();
    }
  };
  expect_error("{\"rig\": \"stereo\", \"platform\": \"stations\"", "not a capture profile");
  expect_error("{\"rig\": \"trinocular\", \"platform\": \"stations\", \"rotation\": \"two_axes\"}",
               "\"rig\"");
  expect_error("{\"rig\": \"stereo\", \"platform\": \"stations\"}", "\"rotation\"");
  expect_error("{\"rig\": \"stereo\", \"platform\": \"moving\", \"rotation\": \"one_axis\"}",
               "one_axis_in_cam");
  EXPECT_THROW(ReadCaptureProfile(dir.File("missing.json")), std::runtime_error);
}

}  // namespace
}  // namespace colmap_lidar
