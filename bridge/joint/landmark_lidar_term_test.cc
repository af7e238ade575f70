#include "bridge/joint/landmark_lidar_term.h"

#include <gtest/gtest.h>

namespace colmap_lidar {
namespace {

// One registered image at the world origin looking along world z, and a landmark per position.
colmap::Reconstruction ModelWithLandmarks(const std::vector<Eigen::Vector3d>& landmarks) {
  colmap::Reconstruction reconstruction;
  reconstruction.AddCamera(colmap::Camera::CreateFromModelName(1, "PINHOLE", 600, 1242, 375));
  colmap::Image image;
  image.SetImageId(1);
  image.SetCameraId(1);
  image.SetName("left/0.png");
  reconstruction.AddImage(image);
  reconstruction.RegisterImage(1);
  for (const Eigen::Vector3d& landmark : landmarks) {
    reconstruction.AddPoint3D(landmark, colmap::Track());
  }
  return reconstruction;
}

// The LiDAR 0.3 m above the camera (camera y points down), its axes x forward, y left, z up: a
// camera axis' surfaces are told apart after the rotation, and residuals are signed towards the
// sensor.
TEST(SummariseByFacingAxis, CountsEachSurfaceByTheCameraAxisItFacesWithSignedResiduals) {
  Eigen::Matrix3d cam_from_lidar_rotation;
  cam_from_lidar_rotation << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const colmap::Rigid3d cam_from_lidar(Eigen::Quaterniond(cam_from_lidar_rotation),
                                       Eigen::Vector3d(0, -0.3, 0));
  const colmap::Rigid3d lidar_from_cam = colmap::Inverse(cam_from_lidar);
  // Two landmarks on the ground (1.65 m below the camera), 10 and 20 mm above the LiDAR's ground
  // plane; one on a wall to the right, 5 mm behind the LiDAR's wall.
  const colmap::Reconstruction reconstruction = ModelWithLandmarks(
      {Eigen::Vector3d(0.5, 1.64, 8), Eigen::Vector3d(-1, 1.63, 12), Eigen::Vector3d(4.005, 0, 9)});
  const Eigen::Vector3d up_in_lidar(0, 0, 1), left_in_lidar(0, 1, 0);  // facing the sensor
  std::vector<LandmarkPlaneObservation> observations = {
      {1, 1, lidar_from_cam * Eigen::Vector3d(0, 1.65, 5), up_in_lidar, false},
      {1, 2, lidar_from_cam * Eigen::Vector3d(2, 1.65, 15), up_in_lidar, false},
      {1, 3, lidar_from_cam * Eigen::Vector3d(4, 1, 6), left_in_lidar, false},
      {1, 3, lidar_from_cam * Eigen::Vector3d(4, 1, 6), left_in_lidar, true}};  // an outlier
  const std::array<LandmarkPlaneFacing, 3> facing =
      SummariseByFacingAxis(observations, reconstruction, cam_from_lidar);
  EXPECT_EQ(facing[0].num_observations, 1u);
  EXPECT_EQ(facing[1].num_observations, 2u);
  EXPECT_EQ(facing[2].num_observations, 0u);
  EXPECT_NEAR(facing[1].mean_residual_m, 0.015, 1e-9);
  EXPECT_NEAR(facing[1].rms_residual_m, std::sqrt((0.01 * 0.01 + 0.02 * 0.02) / 2), 1e-9);
  EXPECT_NEAR(facing[0].mean_residual_m, -0.005, 1e-9);
  EXPECT_DOUBLE_EQ(facing[2].rms_residual_m, 0);
}

}  // namespace
}  // namespace colmap_lidar
