// Accuracy and coverage of a dense model's depth maps (the densifier's COLMAP dense workspace,
// DENSE/stereo/depth_maps/<image>.geometric.bin) against true depth maps (the simulator writes
// ground_truth/depth/<station>.bin, COLMAP's DepthMap format, z-depth in metres per left-image pixel;
// the station is the image name's stem). Frame-free: both are depths along the same camera's axis,
// so a drive, whose structure-based evaluation has little to measure, is evaluated everywhere.
// Quantiles come from histograms (0.1 mm bins up to 2 m): the evaluation streams image by image.
#pragma once

#include <string>
#include <vector>

namespace colmap_lidar {

struct DenseDepthStatistics {
  size_t num_pixels = 0;      // of the images with a true depth map
  size_t num_with_depth = 0;  // pixels the dense model gives a depth
  size_t num_compared = 0;    // ... where the truth has one too (not sky)
  double coverage = 0;        // num_with_depth / num_pixels
  double mean_error_m = 0;    // signed (dense - true): a bias
  double median_abs_error_m = 0;
  double p90_abs_error_m = 0;
  double p99_abs_error_m = 0;
  double median_abs_relative_error = 0;  // |dense - true| / true
  double within_1cm = 0;                 // fractions of num_compared
  double within_5cm = 0;
};

struct DenseDepthEvaluation {
  std::vector<std::string> image_names;         // with a true depth map
  std::vector<DenseDepthStatistics> per_image;  // parallel to image_names
  DenseDepthStatistics all;
  std::vector<std::string> images_without_truth;
  // Dense maps of another size than their true map (a camera with distortion, undistorted to
  // another grid): not compared.
  std::vector<std::string> images_of_another_size;
  // |dense - true| of every k-th compared pixel (at most about a million), for plots.
  std::vector<double> abs_error_sample;
};

// Throws std::runtime_error naming the file when the workspace has no fusion.cfg or a depth map is
// missing or unreadable.
DenseDepthEvaluation EvaluateDenseDepth(const std::string& dense_path,
                                        const std::string& true_depth_path);

}  // namespace colmap_lidar
