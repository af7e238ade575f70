#include "colmap_ext/depth_prior_evaluation.h"

#include "colmap_ext/dense_workspace.h"
#include "colmap_ext/extension_database.h"
#include "colmap_ext/logging.h"

#include "colmap/math/math.h"
#include "colmap/scene/database.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

struct ImageKeypoints {
  std::string name;
  int width = 0, height = 0;
  colmap::FeatureKeypoints keypoints;
};

std::map<colmap::image_t, ImageKeypoints> ReadImageKeypoints(const std::string& database_path) {
  const colmap::Database database(database_path);
  std::map<colmap::image_t, ImageKeypoints> images;
  for (const colmap::Image& image : database.ReadAllImages()) {
    const colmap::Camera camera = database.ReadCamera(image.CameraId());
    ImageKeypoints& entry = images[image.ImageId()];
    entry.name = image.Name();
    entry.width = static_cast<int>(camera.width);
    entry.height = static_cast<int>(camera.height);
    entry.keypoints = database.ReadKeypoints(image.ImageId());
  }
  return images;
}

// True when the true depth within `radius` of (col, row) spans more than `relative_jump` of its
// smallest value, or has holes (sky next to a surface).
bool AtDepthEdge(const cv::Mat& truth,
                 int col,
                 int row,
                 const DepthPriorEvaluationOptions& options) {
  double lo = std::numeric_limits<double>::max(), hi = 0;
  for (int r = row - options.edge_radius_px; r <= row + options.edge_radius_px; ++r) {
    for (int c = col - options.edge_radius_px; c <= col + options.edge_radius_px; ++c) {
      if (c < 0 || r < 0 || c >= truth.cols || r >= truth.rows) continue;
      const double depth = truth.at<float>(r, c);
      if (!(depth > 0)) return true;
      lo = std::min(lo, depth);
      hi = std::max(hi, depth);
    }
  }
  return hi - lo > options.edge_relative_jump * lo;
}

// The priors of one image against its true depth map; priors on pixels without truth are counted.
void EvaluateImagePriors(const ImageKeypoints& image,
                         const std::vector<DepthPrior>& priors,
                         const cv::Mat& truth,
                         const DepthPriorEvaluationOptions& options,
                         DepthPriorEvaluation* evaluation) {
  for (const DepthPrior& prior : priors) {
    THROW_CHECK_LT(prior.point2D_idx, image.keypoints.size())
        << "depth prior of a keypoint that " << image.name << " does not have";
    const colmap::FeatureKeypoint& keypoint = image.keypoints[prior.point2D_idx];
    const int col = static_cast<int>(std::floor(keypoint.x));
    const int row = static_cast<int>(std::floor(keypoint.y));
    const double true_depth = (col >= 0 && row >= 0 && col < truth.cols && row < truth.rows)
                                  ? truth.at<float>(row, col)
                                  : 0;
    if (!(true_depth > 0)) {
      ++evaluation->num_without_true_depth;
      continue;
    }
    DepthPriorError error;
    error.prior_depth = prior.depth;
    error.sigma = prior.sigma;
    error.true_depth = true_depth;
    error.at_edge = AtDepthEdge(truth, col, row, options);
    evaluation->errors.push_back(error);
  }
}

}  // namespace

bool DepthPriorEvaluationOptions::Check() const {
  CHECK_OPTION_GE(edge_radius_px, 0);
  CHECK_OPTION_GE(edge_relative_jump, 0);
  CHECK_OPTION_GT(inlier_sigmas, 0);
  return true;
}

DepthPriorStatistics SummarizeDepthPriorErrors(const std::vector<DepthPriorError>& errors) {
  DepthPriorStatistics statistics;
  statistics.num_priors = errors.size();
  if (errors.empty()) return statistics;
  std::vector<double> abs_relative;
  double sum_relative = 0, sum_normalized = 0;
  size_t within[3] = {0, 0, 0}, beyond_10 = 0;
  for (const DepthPriorError& error : errors) {
    abs_relative.push_back(std::abs(error.Relative()));
    sum_relative += error.Relative();
    sum_normalized += error.Normalized();
    const double normalized = std::abs(error.Normalized());
    for (int k = 0; k < 3; ++k) within[k] += normalized <= k + 1;
    beyond_10 += normalized > 10;
  }
  const double n = static_cast<double>(errors.size());
  statistics.median_abs_relative_error = colmap::Median(abs_relative);
  statistics.mean_relative_error = sum_relative / n;
  statistics.mean_normalized_error = sum_normalized / n;
  statistics.within_1_sigma = within[0] / n;
  statistics.within_2_sigma = within[1] / n;
  statistics.within_3_sigma = within[2] / n;
  statistics.beyond_10_sigma = beyond_10 / n;
  return statistics;
}

DepthPriorEvaluation EvaluateDepthPriors(const std::string& database_path,
                                         const std::string& true_depth_path,
                                         const DepthPriorEvaluationOptions& options) {
  THROW_CHECK(options.Check());
  // Our connection first: it refuses a missing or non-COLMAP file before COLMAP would create one.
  const ExtensionDatabase extension(database_path, ExtensionDatabase::Mode::kReadOnly);
  const std::map<colmap::image_t, ImageKeypoints> images = ReadImageKeypoints(database_path);
  DepthPriorEvaluation evaluation;
  for (const auto& [image_id, image] : images) {
    const fs::path map_path =
        fs::path(true_depth_path) / (fs::path(image.name).stem().string() + ".bin");
    if (!fs::is_regular_file(map_path)) {
      evaluation.images_without_truth.push_back(image.name);
      continue;
    }
    // The fuzzed reader: a truncated or foreign file is one error naming it.
    const cv::Mat truth = ReadColmapDepthMap(map_path.string());
    if (truth.cols != image.width || truth.rows != image.height) {
      throw std::runtime_error(map_path.string() + " is not " + std::to_string(image.width) + "x" +
                               std::to_string(image.height) + " like image " + image.name +
                               ": the true depth belongs to another dataset");
    }
    EvaluateImagePriors(image, extension.ReadDepthPriors(image_id), truth, options, &evaluation);
  }
  if (evaluation.images_without_truth.size() == images.size()) {
    throw std::runtime_error("no image of " + database_path + " has a true depth map in " +
                             true_depth_path);
  }
  std::vector<DepthPriorError> at_edges, away, inliers;
  for (const DepthPriorError& error : evaluation.errors) {
    (error.at_edge ? at_edges : away).push_back(error);
    if (std::abs(error.Normalized()) <= options.inlier_sigmas) inliers.push_back(error);
  }
  evaluation.all = SummarizeDepthPriorErrors(evaluation.errors);
  evaluation.at_edges = SummarizeDepthPriorErrors(at_edges);
  evaluation.away_from_edges = SummarizeDepthPriorErrors(away);
  evaluation.inliers = SummarizeDepthPriorErrors(inliers);
  return evaluation;
}

}  // namespace colmap_lidar
