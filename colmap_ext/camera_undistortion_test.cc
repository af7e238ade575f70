#include "colmap_ext/camera_undistortion.h"

#include "colmap/image/undistortion.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace colmap_lidar {
namespace {

// A plane z = 2 + 0.3 x seen by a camera with strong radial distortion: the depth map in the distorted
// grid, undistorted, must give the plane's depth along every undistorted pixel's ray.
TEST(CameraUndistorter, DepthMapOfAPlaneMatchesThePlaneInThePinholeGrid) {
  const colmap::Camera distorted = colmap::Camera::CreateFromModelName(1, "OPENCV", 150, 200, 150);
  colmap::Camera camera = distorted;
  camera.params = {150, 152, 101, 74, -0.25, 0.05, 0.001, -0.001};
  const colmap::Camera pinhole = colmap::UndistortCamera(colmap::UndistortCameraOptions(), camera);
  ASSERT_EQ(pinhole.ModelName(), "PINHOLE");
  auto plane_depth = [](const Eigen::Vector2d& point_in_cam) {
    return 2.0 / (1 - 0.3 * point_in_cam.x());  // z = 2 + 0.3 x with x = z * u
  };
  cv::Mat depth(150, 200, CV_32F);
  for (int row = 0; row < depth.rows; ++row) {
    for (int col = 0; col < depth.cols; ++col) {
      depth.at<float>(row, col) =
          static_cast<float>(plane_depth(camera.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5))));
    }
  }
  const CameraUndistorter undistorter(camera, pinhole);
  const cv::Mat undistorted = undistorter.UndistortDepthMap(depth);
  ASSERT_EQ(undistorted.cols, static_cast<int>(pinhole.width));
  std::vector<double> errors;
  for (int row = 0; row < undistorted.rows; ++row) {
    for (int col = 0; col < undistorted.cols; ++col) {
      const float z = undistorted.at<float>(row, col);
      if (z <= 0) continue;
      errors.push_back(
          std::abs(z - plane_depth(pinhole.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5)))));
    }
  }
  ASSERT_GT(errors.size(), undistorted.total() * 9 / 10);
  std::sort(errors.begin(), errors.end());
  // Nearest-pixel resampling: within about a pixel of the plane's depth slope (4-6 mm/px here).
  EXPECT_LT(errors[errors.size() / 2], 0.0015);
  EXPECT_LT(errors.back(), 0.008);
  // Without undistortion (the distorted map read as if pinhole) the error is far larger.
  double unresampled_max = 0;
  for (int row = 0; row < std::min(depth.rows, undistorted.rows); ++row) {
    for (int col = 0; col < std::min(depth.cols, undistorted.cols); ++col) {
      unresampled_max = std::max(
          unresampled_max,
          std::abs(depth.at<float>(row, col) -
                   plane_depth(pinhole.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5)))));
    }
  }
  EXPECT_GT(unresampled_max, 0.02);
  EXPECT_THROW(undistorter.UndistortDepthMap(cv::Mat(10, 10, CV_32F)), std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
