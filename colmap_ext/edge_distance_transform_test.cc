#include "colmap_ext/edge_distance_transform.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace colmap_lidar {
namespace {

// The definition, by a scan over all q: alpha E(p) + (1 - alpha) max_q E(q) gamma^max(|dx|,|dy|).
float BruteForce(const cv::Mat& edges, int row, int col, double alpha, double gamma) {
  double largest = 0;
  for (int r = 0; r < edges.rows; ++r) {
    for (int c = 0; c < edges.cols; ++c) {
      const int d = std::max(std::abs(r - row), std::abs(c - col));
      largest = std::max(largest, edges.at<float>(r, c) * std::pow(gamma, d));
    }
  }
  return float(alpha * edges.at<float>(row, col) + (1 - alpha) * largest);
}

TEST(EdgeDistanceTransform, TwoPassesEqualTheDefinition) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> value(0, 255);
  cv::Mat edges(23, 31, CV_32F, cv::Scalar(0));
  for (int k = 0; k < 12; ++k) {  // sparse edges of random strength
    edges.at<float>(rng() % edges.rows, rng() % edges.cols) = value(rng);
  }
  EdgeDistanceTransformOptions options;
  options.gamma = 0.9;  // decays within the image, so that the max is not always the strongest edge
  const cv::Mat transform = InverseDistanceTransform(edges, options);
  for (int row = 0; row < edges.rows; ++row) {
    for (int col = 0; col < edges.cols; ++col) {
      ASSERT_NEAR(transform.at<float>(row, col),
                  BruteForce(edges, row, col, options.alpha, options.gamma),
                  1e-3)
          << row << " " << col;
    }
  }
}

TEST(EdgeDistanceTransform, EdgeImageIsTheLargestStepToAnEightNeighbour) {
  cv::Mat image(5, 6, CV_8UC1, cv::Scalar(10));
  image.at<uint8_t>(2, 3) = 200;
  const cv::Mat edges = EdgeImage(image);
  for (int row = 0; row < 5; ++row) {
    for (int col = 0; col < 6; ++col) {
      const bool touches = std::abs(row - 2) <= 1 && std::abs(col - 3) <= 1;
      EXPECT_EQ(edges.at<float>(row, col), touches ? 190.f : 0.f) << row << " " << col;
    }
  }
  EdgeDistanceTransformOptions options;
  options.gamma = 1.0;
  EXPECT_FALSE(options.Check());
}

}  // namespace
}  // namespace colmap_lidar
