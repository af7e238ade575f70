// Resampling from a distorted camera's pixel grid to the undistorted PINHOLE camera COLMAP derives from
// it (colmap::UndistortCamera), for images and for depth maps: the dense workspace and the densifier
// work in undistorted pinhole cameras, while stereo depth maps live in the original left grid.
#pragma once

#include "colmap/scene/camera.h"

#include <opencv2/core.hpp>

namespace colmap_lidar {

class CameraUndistorter {
 public:
  CameraUndistorter(const colmap::Camera& distorted, const colmap::Camera& undistorted);

  // Bilinear (8-bit images of the distorted camera's size).
  cv::Mat UndistortImage(const cv::Mat& image) const;
  // Nearest pixel: never blends depths across an edge. z-depth is unchanged by the resampling (both
  // cameras share the frame and the optical axis). Throws std::invalid_argument for a wrong size.
  cv::Mat UndistortDepthMap(const cv::Mat& depth) const;

 private:
  int distorted_width_ = 0, distorted_height_ = 0;
  cv::Mat map_x_,
      map_y_;  // CV_32F, undistorted grid -> OpenCV coordinates in the distorted grid
};

}  // namespace colmap_lidar
