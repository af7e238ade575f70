#include "colmap_ext/stereo_rectifier.h"

#include <gtest/gtest.h>

#include <cmath>

namespace colmap_lidar {
namespace {

// A rig with distortion and a rotated right camera, as after a real calibration.
void MakeRig(colmap::Camera* left, colmap::Camera* right, colmap::Rigid3d* right_from_left) {
  *left = colmap::Camera::CreateFromModelName(1, "OPENCV", 800, 640, 480);
  left->params = {800, 805, 321.3, 238.1, -0.08, 0.02, 0.0005, -0.0003};
  *right = colmap::Camera::CreateFromModelName(2, "OPENCV", 800, 640, 480);
  right->params = {810, 812, 317.9, 242.6, -0.07, 0.015, -0.0002, 0.0004};
  right_from_left->rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.3, 1, 0.2).normalized()));
  right_from_left->translation = Eigen::Vector3d(-0.38, 0.004, -0.002);
}

// Z-depth in the original left camera of a plane n.x = offset (left frame) along a ray.
double PlaneDepthAlongRay(const Eigen::Vector3d& ray,
                          const Eigen::Vector3d& normal,
                          double offset) {
  return (offset / normal.dot(ray)) * ray.z();
}

TEST(StereoRectifier, DisparityOfAPlaneGivesItsDepthInTheOriginalLeftGrid) {
  colmap::Camera left, right;
  colmap::Rigid3d right_from_left;
  MakeRig(&left, &right, &right_from_left);
  const StereoRectifier rectifier(left, right, right_from_left);
  EXPECT_NEAR(rectifier.BaselineMeters(), right_from_left.translation.norm(), 1e-9);

  // A slanted plane 2-3 m in front of the left camera.
  const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -0.1, 1).normalized();
  const double offset = 2.5;
  // Its exact disparity in the rectified left image: Z_rect = f b / d.
  const cv::Matx33d left_from_rectified = rectifier.LeftFromRectified();
  const cv::Point2d principal = rectifier.RectifiedPrincipalPoint();
  const double f = rectifier.RectifiedFocalLength();
  cv::Mat disparity(480, 640, CV_32F);
  for (int row = 0; row < 480; ++row) {
    for (int col = 0; col < 640; ++col) {
      const cv::Vec3d ray_rect((col - principal.x) / f, (row - principal.y) / f, 1);
      const cv::Vec3d ray_left = left_from_rectified * ray_rect;
      const Eigen::Vector3d ray(ray_left[0], ray_left[1], ray_left[2]);
      const double t = offset / normal.dot(ray);  // point = t * ray
      const double z_rect = t;                    // ray_rect has unit z
      disparity.at<float>(row, col) = static_cast<float>(f * rectifier.BaselineMeters() / z_rect);
    }
  }
  const cv::Mat depth = rectifier.DepthInLeftImage(disparity);
  // Every interior pixel: the plane's depth along the COLMAP ray through the pixel centre.
  double max_relative_error = 0;
  int num_checked = 0;
  for (int row = 20; row < 460; row += 7) {
    for (int col = 20; col < 620; col += 7) {
      const Eigen::Vector2d uv = left.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5));
      const double truth = PlaneDepthAlongRay(uv.homogeneous(), normal, offset);
      const double z = depth.at<float>(row, col);
      ASSERT_GT(z, 0) << row << " " << col;
      max_relative_error = std::max(max_relative_error, std::abs(z - truth) / truth);
      ++num_checked;
    }
  }
  EXPECT_GT(num_checked, 5000);
  // Bilinear disparity interpolation of a plane's 1/Z is exact up to its curvature: far below 0.01 %.
  EXPECT_LT(max_relative_error, 1e-4);
}

TEST(StereoRectifier, RejectsUnsupportedModelsAndDifferentSizes) {
  colmap::Camera left, right;
  colmap::Rigid3d right_from_left;
  MakeRig(&left, &right, &right_from_left);
  colmap::Camera fisheye = colmap::Camera::CreateFromModelName(1, "OPENCV_FISHEYE", 800, 640, 480);
  try {
    StereoRectifier rectifier(fisheye, right, right_from_left);
    FAIL() << "a fisheye camera was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("OPENCV_FISHEYE"), std::string::npos);
  }
  colmap::Camera smaller = right;
  smaller.width = 600;
  EXPECT_THROW(StereoRectifier(left, smaller, right_from_left), std::invalid_argument);
}

TEST(CameraToOpenCv, ShiftsThePrincipalPointToOpenCvsPixelConvention) {
  const colmap::Camera camera =
      colmap::Camera::CreateFromModelName(1, "SIMPLE_RADIAL", 500, 100, 80);
  cv::Mat k, d;
  CameraToOpenCv(camera, &k, &d);
  EXPECT_DOUBLE_EQ(k.at<double>(0, 2), 50 - 0.5);
  EXPECT_DOUBLE_EQ(k.at<double>(1, 2), 40 - 0.5);
  EXPECT_EQ(d.total(), 4u);
}

}  // namespace
}  // namespace colmap_lidar
