// The image side of the edge-based calibration of Levinson & Thrun ("Automatic Online Calibration of
// Cameras and Lasers", RSS 2013):
//   edge image         E(p) = max |I(p) - I(q)| over the 8 neighbours q of p;
//   inverse distance   D(p) = alpha E(p) + (1 - alpha) max_q E(q) gamma^max(|dx|, |dy|),
// so a projected depth edge scores where an image edge is, and still some way off it (gamma = 0.98
// keeps 36 % at 50 px): the objective is smooth enough for a grid search to climb.
// The max over all q is computed exactly in linear time by two passes (a chessboard-distance
// transform with a multiplicative decay), not a window scan.
#pragma once

#include <opencv2/core.hpp>

namespace colmap_lidar {

struct EdgeDistanceTransformOptions {
  // Gaussian blur of the image before E [px]; 0: none (Levinson & Thrun). Fine texture (stone, rust,
  // the simulator's albedo) makes E high everywhere on a surface, so that J prefers points anywhere
  // inside a textured face to points on its outline; a blur keeps the outlines, which have contrast
  // at every scale, and flattens the texture.
  double blur_sigma_px = 0.0;
  double alpha = 1.0 / 3.0;
  double gamma = 0.98;

  bool Check() const;
};

// An 8-bit grey copy of an 8-bit grey or BGR image (never a view: callers blur it in place).
cv::Mat GreyImage(const cv::Mat& image);

// CV_8UC1 (or CV_8UC3, converted to grey) -> CV_32F edge image E (of the blurred image if
// blur_sigma_px > 0).
cv::Mat EdgeImage(const cv::Mat& image, double blur_sigma_px = 0.0);

// CV_32F edge image E -> CV_32F D.
cv::Mat InverseDistanceTransform(const cv::Mat& edges, const EdgeDistanceTransformOptions& options);

}  // namespace colmap_lidar
