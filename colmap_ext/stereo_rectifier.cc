#include "colmap_ext/stereo_rectifier.h"

#include "colmap_ext/logging.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <stdexcept>

namespace colmap_lidar {

void CameraToOpenCv(const colmap::Camera& camera, cv::Mat* camera_matrix, cv::Mat* distortion) {
  const std::vector<double>& p = camera.params;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::vector<double> coefficients;
  const std::string model = camera.ModelName();
  if (model == "SIMPLE_PINHOLE" || model == "SIMPLE_RADIAL" || model == "RADIAL") {
    fx = fy = p[0];
    cx = p[1];
    cy = p[2];
    if (model == "SIMPLE_RADIAL") coefficients = {p[3], 0, 0, 0};
    if (model == "RADIAL") coefficients = {p[3], p[4], 0, 0};
  } else if (model == "PINHOLE" || model == "OPENCV" || model == "FULL_OPENCV") {
    fx = p[0];
    fy = p[1];
    cx = p[2];
    cy = p[3];
    // COLMAP's OPENCV / FULL_OPENCV parameters follow OpenCV's own order.
    coefficients.assign(p.begin() + 4, p.end());
  } else {
    throw std::invalid_argument("camera model " + model +
                                " is not supported for stereo rectification (use SIMPLE_PINHOLE, "
                                "PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV or FULL_OPENCV)");
  }
  if (coefficients.empty()) coefficients = {0, 0, 0, 0};
  // COLMAP's pixel centres are at +0.5, OpenCV's at integers.
  *camera_matrix = (cv::Mat_<double>(3, 3) << fx, 0, cx - 0.5, 0, fy, cy - 0.5, 0, 0, 1);
  *distortion = cv::Mat(coefficients, true).reshape(1, 1);
}

namespace {

// Every pixel of the original left image in the rectified image (row-major).
std::vector<cv::Point2f> RectifiedPixelGrid(const cv::Size& size,
                                            const cv::Mat& camera_matrix,
                                            const cv::Mat& distortion,
                                            const cv::Mat& rectification,
                                            const cv::Mat& projection) {
  std::vector<cv::Point2f> pixels;
  pixels.reserve(static_cast<size_t>(size.area()));
  for (int row = 0; row < size.height; ++row) {
    for (int col = 0; col < size.width; ++col) {
      pixels.emplace_back(static_cast<float>(col), static_cast<float>(row));
    }
  }
  std::vector<cv::Point2f> rectified;
  cv::undistortPoints(pixels, rectified, camera_matrix, distortion, rectification, projection);
  return rectified;
}

}  // namespace

StereoRectifier::StereoRectifier(const colmap::Camera& left,
                                 const colmap::Camera& right,
                                 const colmap::Rigid3d& right_from_left) {
  if (left.width != right.width || left.height != right.height) {
    throw std::invalid_argument("left and right cameras differ in size (" +
                                std::to_string(left.width) + "x" + std::to_string(left.height) +
                                " vs " + std::to_string(right.width) + "x" +
                                std::to_string(right.height) + ")");
  }
  size_ = cv::Size(static_cast<int>(left.width), static_cast<int>(left.height));
  cv::Mat k_left, d_left, k_right, d_right;
  CameraToOpenCv(left, &k_left, &d_left);
  CameraToOpenCv(right, &k_right, &d_right);
  cv::Mat rotation, translation;
  cv::eigen2cv(Eigen::Matrix3d(right_from_left.rotation.toRotationMatrix()), rotation);
  cv::eigen2cv(Eigen::Vector3d(right_from_left.translation), translation);

  cv::Mat r1, r2, p1, p2, q;
  // alpha = 1: every original pixel keeps a rectified counterpart; zero disparity at infinity.
  cv::stereoRectify(k_left,
                    d_left,
                    k_right,
                    d_right,
                    size_,
                    rotation,
                    translation,
                    r1,
                    r2,
                    p1,
                    p2,
                    q,
                    cv::CALIB_ZERO_DISPARITY,
                    1.0,
                    size_);
  THROW_CHECK_LT(std::abs(p2.at<double>(1, 3)), 1e-6 * std::abs(p2.at<double>(0, 3)))
      << "only horizontal stereo rigs are supported (right camera beside the "
         "left one)";
  rectified_focal_ = p1.at<double>(0, 0);
  rectified_cx_ = p1.at<double>(0, 2);
  rectified_cy_ = p1.at<double>(1, 2);
  baseline_ = std::abs(p2.at<double>(0, 3)) / p2.at<double>(0, 0);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) left_from_rectified_(i, j) = r1.at<double>(j, i);
  }
  cv::initUndistortRectifyMap(k_left, d_left, r1, p1, size_, CV_32FC1, left_map_x_, left_map_y_);
  cv::remap(cv::Mat(size_, CV_8U, cv::Scalar(255)),
            left_mask_,
            left_map_x_,
            left_map_y_,
            cv::INTER_NEAREST,
            cv::BORDER_CONSTANT,
            0);
  cv::initUndistortRectifyMap(
      k_right, d_right, r2, p2, size_, CV_32FC1, right_map_x_, right_map_y_);

  const std::vector<cv::Point2f> rectified = RectifiedPixelGrid(size_, k_left, d_left, r1, p1);
  original_in_rectified_ = cv::Mat(rectified, true).reshape(2, size_.height);
}

void StereoRectifier::Rectify(const cv::Mat& left_image,
                              const cv::Mat& right_image,
                              cv::Mat* left_rectified,
                              cv::Mat* right_rectified) const {
  THROW_CHECK(left_image.size() == size_ && right_image.size() == size_)
      << "image size differs from the rig's camera size";
  cv::remap(left_image,
            *left_rectified,
            left_map_x_,
            left_map_y_,
            cv::INTER_LINEAR,
            cv::BORDER_CONSTANT,
            0);
  cv::remap(right_image,
            *right_rectified,
            right_map_x_,
            right_map_y_,
            cv::INTER_LINEAR,
            cv::BORDER_CONSTANT,
            0);
}

cv::Mat StereoRectifier::ToLeftImage(const cv::Mat& rectified) const {
  THROW_CHECK(rectified.size() == size_);
  cv::Mat original;
  cv::remap(rectified,
            original,
            original_in_rectified_,
            cv::noArray(),
            cv::INTER_NEAREST,
            cv::BORDER_CONSTANT,
            0);
  return original;
}

cv::Mat StereoRectifier::DepthInLeftImage(const cv::Mat& left_disparity,
                                          float max_disparity_jump) const {
  THROW_CHECK(left_disparity.type() == CV_32F && left_disparity.size() == size_);
  cv::Mat depth(size_, CV_32F, cv::Scalar(0));
  const int width = size_.width;
  const int height = size_.height;
  auto disparity_at = [&](int col, int row) -> float {
    if (col < 0 || row < 0 || col >= width || row >= height) return 0.f;
    return left_disparity.at<float>(row, col);
  };
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const cv::Point2f uv = original_in_rectified_.at<cv::Point2f>(row, col);
      const int c0 = static_cast<int>(std::floor(uv.x));
      const int r0 = static_cast<int>(std::floor(uv.y));
      const float fx = uv.x - c0;
      const float fy = uv.y - r0;
      const float d00 = disparity_at(c0, r0), d10 = disparity_at(c0 + 1, r0),
                  d01 = disparity_at(c0, r0 + 1), d11 = disparity_at(c0 + 1, r0 + 1);
      float disparity = 0.f;
      const float lo = std::min(std::min(d00, d10), std::min(d01, d11));
      const float hi = std::max(std::max(d00, d10), std::max(d01, d11));
      if (lo > 0.f && hi - lo <= max_disparity_jump) {
        disparity = (1 - fy) * ((1 - fx) * d00 + fx * d10) + fy * ((1 - fx) * d01 + fx * d11);
      } else {
        disparity =
            disparity_at(static_cast<int>(std::lround(uv.x)), static_cast<int>(std::lround(uv.y)));
      }
      if (disparity <= 0.f) continue;
      // Eq. (stereo): Z = f b / d in the rectified frame, then back to the original left camera.
      const double z = rectified_focal_ * baseline_ / disparity;
      const cv::Vec3d point_in_rectified((uv.x - rectified_cx_) / rectified_focal_ * z,
                                         (uv.y - rectified_cy_) / rectified_focal_ * z,
                                         z);
      const cv::Vec3d point_in_left = left_from_rectified_ * point_in_rectified;
      if (point_in_left[2] > 0) {
        depth.at<float>(row, col) = static_cast<float>(point_in_left[2]);
      }
    }
  }
  return depth;
}

}  // namespace colmap_lidar
