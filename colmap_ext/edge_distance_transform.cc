#include "colmap_ext/edge_distance_transform.h"

#include "colmap_ext/logging.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>

namespace colmap_lidar {

bool EdgeDistanceTransformOptions::Check() const {
  CHECK_OPTION_GE(blur_sigma_px, 0);
  CHECK_OPTION_GE(alpha, 0);
  CHECK_OPTION_LE(alpha, 1);
  CHECK_OPTION_GT(gamma, 0);
  CHECK_OPTION_LT(gamma, 1);
  return true;
}

cv::Mat GreyImage(const cv::Mat& image) {
  THROW_CHECK(!image.empty());
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image.clone();
  }
  THROW_CHECK_EQ(grey.type(), CV_8UC1);
  return grey;
}

cv::Mat EdgeImage(const cv::Mat& image, double blur_sigma_px) {
  cv::Mat grey = GreyImage(image);
  if (blur_sigma_px > 0) cv::GaussianBlur(grey, grey, cv::Size(), blur_sigma_px);
  // max_q |I(p) - I(q)| over the 3x3 neighbourhood = max(dilate(I) - I, I - erode(I)); OpenCV's
  // default border of dilate/erode leaves pixels outside the image out.
  cv::Mat dilated, eroded, edges;
  cv::dilate(grey, dilated, cv::Mat());
  cv::erode(grey, eroded, cv::Mat());
  cv::subtract(dilated, grey, dilated);
  cv::subtract(grey, eroded, eroded);
  cv::max(dilated, eroded, edges);
  edges.convertTo(edges, CV_32F);
  return edges;
}

cv::Mat InverseDistanceTransform(const cv::Mat& edges,
                                 const EdgeDistanceTransformOptions& options) {
  THROW_CHECK(options.Check());
  THROW_CHECK_EQ(edges.type(), CV_32F);
  // M(p) = max_q E(q) gamma^d_inf(p, q). Every chessboard path from q to p can be taken as steps that
  // go first only down/right-ish (forward pass: from the left, up-left, up, up-right) and then only
  // up/left-ish (backward pass), and the decay is multiplicative along it, so the two passes are exact.
  cv::Mat largest = edges.clone();
  const float gamma = float(options.gamma);
  auto relax = [&](int row, int col, int r, int c) {
    if (r < 0 || c < 0 || r >= largest.rows || c >= largest.cols) return;
    float& m = largest.at<float>(row, col);
    m = std::max(m, gamma * largest.at<float>(r, c));
  };
  for (int row = 0; row < largest.rows; ++row) {
    for (int col = 0; col < largest.cols; ++col) {
      relax(row, col, row, col - 1);
      relax(row, col, row - 1, col - 1);
      relax(row, col, row - 1, col);
      relax(row, col, row - 1, col + 1);
    }
  }
  for (int row = largest.rows - 1; row >= 0; --row) {
    for (int col = largest.cols - 1; col >= 0; --col) {
      relax(row, col, row, col + 1);
      relax(row, col, row + 1, col + 1);
      relax(row, col, row + 1, col);
      relax(row, col, row + 1, col - 1);
    }
  }
  cv::Mat transform;
  cv::addWeighted(edges, options.alpha, largest, 1 - options.alpha, 0, transform);
  return transform;
}

}  // namespace colmap_lidar
