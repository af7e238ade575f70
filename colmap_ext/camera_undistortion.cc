#include "colmap_ext/camera_undistortion.h"

#include <opencv2/imgproc.hpp>

#include <stdexcept>
#include <string>

namespace colmap_lidar {

CameraUndistorter::CameraUndistorter(const colmap::Camera& distorted,
                                     const colmap::Camera& undistorted)
    : distorted_width_(static_cast<int>(distorted.width)),
      distorted_height_(static_cast<int>(distorted.height)) {
  const int width = static_cast<int>(undistorted.width);
  const int height = static_cast<int>(undistorted.height);
  map_x_.create(height, width, CV_32F);
  map_y_.create(height, width, CV_32F);
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      // COLMAP's pixel centres are at +0.5, OpenCV's at integers.
      const Eigen::Vector2d point_in_cam =
          undistorted.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5));
      const Eigen::Vector2d xy = distorted.ImgFromCam(point_in_cam);
      map_x_.at<float>(row, col) = static_cast<float>(xy.x() - 0.5);
      map_y_.at<float>(row, col) = static_cast<float>(xy.y() - 0.5);
    }
  }
}

cv::Mat CameraUndistorter::UndistortImage(const cv::Mat& image) const {
  cv::Mat result;
  cv::remap(
      image, result, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  return result;
}

cv::Mat CameraUndistorter::UndistortDepthMap(const cv::Mat& depth) const {
  if (depth.type() != CV_32F || depth.cols != distorted_width_ || depth.rows != distorted_height_) {
    throw std::invalid_argument("UndistortDepthMap: expected a CV_32F map of " +
                                std::to_string(distorted_width_) + "x" +
                                std::to_string(distorted_height_) + ", got " +
                                std::to_string(depth.cols) + "x" + std::to_string(depth.rows));
  }
  cv::Mat result;
  cv::remap(depth, result, map_x_, map_y_, cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  return result;
}

}  // namespace colmap_lidar
