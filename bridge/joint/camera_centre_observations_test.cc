#include "bridge/joint/camera_centre_observations.h"

#include <gtest/gtest.h>

namespace colmap_lidar {
namespace {

// Cameras at z = 0, 1, 2 driving along their viewing direction +z and landmarks about 20 m ahead; the
// last landmark sits `offset_m` ahead of the third camera's centre (behind it if negative).
colmap::Reconstruction Street(double offset_m) {
  colmap::Reconstruction reconstruction;
  reconstruction.AddCamera(colmap::Camera::CreateFromModelName(1, "PINHOLE", 700, 1000, 400));
  const int kNumLandmarks = 5;
  for (colmap::image_t image_id = 1; image_id <= 3; ++image_id) {
    colmap::Image image;
    image.SetImageId(image_id);
    image.SetCameraId(1);
    image.SetName(std::to_string(image_id) + ".png");
    image.CamFromWorld() =
        colmap::Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -(image_id - 1.0)));
    image.SetPoints2D(std::vector<Eigen::Vector2d>(kNumLandmarks, Eigen::Vector2d(500, 200)));
    reconstruction.AddImage(image);
    reconstruction.RegisterImage(image_id);
  }
  for (int k = 0; k < kNumLandmarks; ++k) {
    const Eigen::Vector3d xyz =
        k + 1 < kNumLandmarks ? Eigen::Vector3d(k, 1, 20) : Eigen::Vector3d(0, 0, 2 + offset_m);
    colmap::Track track;
    for (colmap::image_t image_id = 1; image_id <= 3; ++image_id) track.AddElement(image_id, k);
    reconstruction.AddPoint3D(xyz, track);
  }
  return reconstruction;
}

TEST(CameraCentreObservationsTest, FindsTheObservationOfTheCameraAtWhoseCentreALandmarkSits) {
  for (const double offset_m : {1e-9, -1e-6}) {
    const auto at_centres = ObservationsAtCameraCentres(Street(offset_m));
    ASSERT_EQ(at_centres.size(), 1u) << offset_m;
    EXPECT_EQ(at_centres[0].first, 3u);
    EXPECT_EQ(at_centres[0].second, 4u);
  }
}

TEST(CameraCentreObservationsTest, KeepsNearButRealLandmarks) {
  // 5 cm from the lens is near (a median depth of 20 m), not at the centre.
  EXPECT_TRUE(ObservationsAtCameraCentres(Street(0.05)).empty());
  EXPECT_TRUE(ObservationsAtCameraCentres(colmap::Reconstruction()).empty());
}

}  // namespace
}  // namespace colmap_lidar
