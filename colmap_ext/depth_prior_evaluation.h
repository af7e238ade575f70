// Accuracy of the database's depth priors against true depth maps (the simulator writes them as
// ground_truth/depth/<station>.bin, COLMAP's DepthMap format, z-depth in metres per left-image pixel).
//
// For every prior, the true depth is read at the keypoint's own pixel (COLMAP's convention: pixel
// (col, row) spans [col, col+1) x [row, row+1)). The normalised error (prior - true) / sigma_d tells
// whether sigma_d = d^2/(b f) sigma_p describes the stereo depth at keypoints: a Gaussian puts 68 / 95 /
// 99.7 % within 1 / 2 / 3 sigma. Keypoints near a true depth edge (the true depth in the window of
// `edge_radius_px` spans more than `edge_relative_jump`) are reported apart: block matching fattens the
// foreground there, and SIFT likes edges.
#pragma once

#include <string>
#include <vector>

namespace colmap_lidar {

struct DepthPriorEvaluationOptions {
  // A keypoint is "at an edge" when the true depth within this radius spans more than
  // `edge_relative_jump` of its smallest value.
  int edge_radius_px = 2;
  double edge_relative_jump = 0.05;
  // The `inliers` statistics: priors within this many sigma_d of the truth.
  double inlier_sigmas = 3.0;

  bool Check() const;
};

// One prior against the truth.
struct DepthPriorError {
  double prior_depth = 0;  // metres
  double sigma = 0;        // metres
  double true_depth = 0;   // metres
  bool at_edge = false;

  double Normalized() const { return (prior_depth - true_depth) / sigma; }
  double Relative() const { return (prior_depth - true_depth) / true_depth; }
};

// Summary of a set of priors.
struct DepthPriorStatistics {
  size_t num_priors = 0;
  // median and mean of (prior - true) / true; the mean shows a bias, the median the typical error
  double median_abs_relative_error = 0;
  double mean_relative_error = 0;
  // mean of (prior - true) / sigma: a bias in units of the priors' own sigma
  double mean_normalized_error = 0;
  // fractions with |prior - true| within 1, 2, 3 sigma (Gaussian: 0.683, 0.954, 0.997)
  double within_1_sigma = 0, within_2_sigma = 0, within_3_sigma = 0;
  // fraction beyond 10 sigma: gross errors, which a Gaussian never makes
  double beyond_10_sigma = 0;
};

struct DepthPriorEvaluation {
  std::vector<DepthPriorError> errors;
  // images of the database without a true depth map
  std::vector<std::string> images_without_truth;
  // priors whose keypoint's pixel has no true depth (sky)
  size_t num_without_true_depth = 0;
  DepthPriorStatistics all, at_edges, away_from_edges;
  // The priors within `inlier_sigmas` of the truth: what the joint adjuster's outlier gate keeps, so
  // their mean error is the bias that reaches the solution.
  DepthPriorStatistics inliers;
};

DepthPriorStatistics SummarizeDepthPriorErrors(const std::vector<DepthPriorError>& errors);

// Reads the priors of every image of the database (opened read-only) and the true depth map
// TRUE_DEPTH_PATH/<stem>.bin of each (stem = image file name without extension). Throws
// std::runtime_error naming the file when the database cannot be read, a true depth map is not in
// the image's size, or no image has one.
DepthPriorEvaluation EvaluateDepthPriors(const std::string& database_path,
                                         const std::string& true_depth_path,
                                         const DepthPriorEvaluationOptions& options);

}  // namespace colmap_lidar
