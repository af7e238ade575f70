// Rectification of a station's stereo pair (rig.json intrinsics and right_from_left) with OpenCV, and the
// mapping from rectified disparity back to z-depth in the ORIGINAL left image's pixel grid.
//
// Pixel conventions: COLMAP puts the centre of pixel (col, row) at (col + 0.5, row + 0.5); OpenCV at
// (col, row). The intrinsics from rig.json are COLMAP's; they are shifted by -0.5 px before they reach
// OpenCV, so a depth map written here is aligned with COLMAP's keypoints and cameras.
#pragma once

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"

#include <opencv2/core.hpp>

namespace colmap_lidar {

// The OpenCV form of a COLMAP camera: 3x3 K (OpenCV pixel convention) and distortion coefficients in
// OpenCV's order (k1 k2 p1 p2 [k3 k4 k5 k6]). Supported models: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL,
// RADIAL, OPENCV, FULL_OPENCV; any other model throws std::invalid_argument naming it.
void CameraToOpenCv(const colmap::Camera& camera, cv::Mat* camera_matrix, cv::Mat* distortion);

class StereoRectifier {
 public:
  // Both cameras must have the same image size (throws std::invalid_argument otherwise).
  StereoRectifier(const colmap::Camera& left,
                  const colmap::Camera& right,
                  const colmap::Rigid3d& right_from_left);

  // Rectified 8-bit images (same size as the input).
  void Rectify(const cv::Mat& left_image,
               const cv::Mat& right_image,
               cv::Mat* left_rectified,
               cv::Mat* right_rectified) const;

  // Z-depth [m] in the original left camera of every original left pixel, from a rectified left disparity
  // map (CV_32F, pixels, <= 0 invalid). A pixel's disparity is interpolated bilinearly when its four
  // rectified neighbours are valid and agree within `max_disparity_jump` px, else taken from the nearest
  // rectified pixel; it stays 0 (invalid) when that pixel is invalid.
  cv::Mat DepthInLeftImage(const cv::Mat& left_disparity, float max_disparity_jump = 1.f) const;

  // Nearest-neighbour resampling of a rectified left-image map into the original left grid.
  cv::Mat ToLeftImage(const cv::Mat& rectified) const;

  // 255 where a rectified left pixel comes from inside the original left image, else 0.
  const cv::Mat& LeftRectifiedMask() const { return left_mask_; }

  double RectifiedFocalLength() const { return rectified_focal_; }
  // Principal point of both rectified cameras (OpenCV pixel convention).
  cv::Point2d RectifiedPrincipalPoint() const { return {rectified_cx_, rectified_cy_}; }
  // Rotation from the rectified left camera frame to the original left camera frame (R1^T).
  const cv::Matx33d& LeftFromRectified() const { return left_from_rectified_; }
  double BaselineMeters() const { return baseline_; }
  cv::Size ImageSize() const { return size_; }

 private:
  cv::Size size_;
  double rectified_focal_ = 0;
  double rectified_cx_ = 0;
  double rectified_cy_ = 0;
  double baseline_ = 0;
  cv::Matx33d left_from_rectified_;  // R1^T
  cv::Mat left_map_x_, left_map_y_, right_map_x_, right_map_y_;
  cv::Mat left_mask_;
  // Rectified position (OpenCV convention) of every original left pixel centre.
  cv::Mat original_in_rectified_;  // CV_32FC2
};

}  // namespace colmap_lidar
