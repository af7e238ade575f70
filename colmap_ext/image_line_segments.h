// Straight segments of an image (OpenCV's line segment detector, LSD) and their interpretation
// planes: the plane through the camera centre and a segment contains the segment's 3D line, so its
// unit normal is perpendicular to that line's direction in the camera frame. Vertical segments thus
// measure the vertical in the camera frame (bridge/initialization/vertical_alignment.h). Not part
// of Zhen et al. 2019.
#pragma once

#include "colmap/scene/camera.h"

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace colmap_lidar {

struct LineSegmentOptions {
  // shorter segments are dropped [px of the full-size image]
  double min_length_px = 25;
  // Gaussian blur before detection (0: none): texture noise breaks long edges into short pieces [px]
  double blur_sigma_px = 1.5;
  // detection runs on a copy scaled so that its larger side is at most this [px]
  int max_image_size = 2000;

  bool Check() const;
};

struct LineSegment {
  // COLMAP image coordinates (the first pixel's centre at (0.5, 0.5)) of the full-size image
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  Eigen::Vector2d end = Eigen::Vector2d::Zero();

  double Length() const { return (end - start).norm(); }
};

// Segments of an 8-bit grey or BGR image, longest first.
std::vector<LineSegment> DetectLineSegments(const cv::Mat& image,
                                            const LineSegmentOptions& options);

// Reads `image_path` (a clear error naming it when unreadable) and detects its segments.
std::vector<LineSegment> DetectLineSegments(const std::string& image_path,
                                            const LineSegmentOptions& options);

// Unit normal, in the camera frame (z forward), of the plane through the camera centre and the
// segment's end points (each undistorted through the camera model).
Eigen::Vector3d InterpretationPlaneNormal(const colmap::Camera& camera, const LineSegment& segment);

}  // namespace colmap_lidar
