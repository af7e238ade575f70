#include "colmap_ext/dense_depth_evaluation.h"

#include "colmap_ext/dense_workspace.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// Counts of values in bins of `bin_width` from 0 (the last bin holds everything beyond).
class QuantileHistogram {
 public:
  QuantileHistogram(double bin_width, double max_value)
      : bin_width_(bin_width), counts_(static_cast<size_t>(max_value / bin_width) + 1, 0) {}

  void Add(double value) {
    const double last = static_cast<double>(counts_.size() - 1);
    ++counts_[static_cast<size_t>(std::min(std::max(0.0, value) / bin_width_, last))];
    ++total_;
  }
  void Merge(const QuantileHistogram& other) {
    for (size_t k = 0; k < counts_.size(); ++k) counts_[k] += other.counts_[k];
    total_ += other.total_;
  }
  // The upper edge of the bin holding the q-quantile; 0 without values.
  double Quantile(double q) const {
    if (total_ == 0) return 0;
    const double target = q * static_cast<double>(total_);
    size_t sum = 0;
    for (size_t k = 0; k < counts_.size(); ++k) {
      sum += counts_[k];
      if (static_cast<double>(sum) >= target) return (k + 1) * bin_width_;
    }
    return counts_.size() * bin_width_;
  }
  // Fraction of the values below `value` (bin edges: exact for multiples of the bin width).
  double FractionBelow(double value) const {
    size_t sum = 0;
    const size_t end = std::min(counts_.size(), static_cast<size_t>(value / bin_width_ + 0.5));
    for (size_t k = 0; k < end; ++k) sum += counts_[k];
    return total_ > 0 ? static_cast<double>(sum) / static_cast<double>(total_) : 0;
  }

 private:
  double bin_width_;
  std::vector<size_t> counts_;
  size_t total_ = 0;
};

struct Accumulator {
  QuantileHistogram absolute{1e-4, 2.0};
  QuantileHistogram relative{1e-4, 1.0};
  double signed_sum = 0;
  DenseDepthStatistics statistics;

  void Merge(const Accumulator& other) {
    absolute.Merge(other.absolute);
    relative.Merge(other.relative);
    signed_sum += other.signed_sum;
    statistics.num_pixels += other.statistics.num_pixels;
    statistics.num_with_depth += other.statistics.num_with_depth;
    statistics.num_compared += other.statistics.num_compared;
  }
  DenseDepthStatistics Finish() const {
    DenseDepthStatistics s = statistics;
    const double n = static_cast<double>(std::max<size_t>(1, s.num_compared));
    s.coverage = s.num_pixels > 0 ? static_cast<double>(s.num_with_depth) / s.num_pixels : 0;
    s.mean_error_m = signed_sum / n;
    s.median_abs_error_m = absolute.Quantile(0.5);
    s.p90_abs_error_m = absolute.Quantile(0.9);
    s.p99_abs_error_m = absolute.Quantile(0.99);
    s.median_abs_relative_error = relative.Quantile(0.5);
    s.within_1cm = absolute.FractionBelow(0.01);
    s.within_5cm = absolute.FractionBelow(0.05);
    return s;
  }
};

void CompareImage(const cv::Mat& dense,
                  const cv::Mat& truth,
                  size_t sample_stride,
                  Accumulator* image,
                  std::vector<double>* sample) {
  image->statistics.num_pixels += dense.total();
  for (int row = 0; row < dense.rows; ++row) {
    for (int col = 0; col < dense.cols; ++col) {
      // No depth: 0, negative or not finite (NaN, inf), in either map.
      const float d = dense.at<float>(row, col), t = truth.at<float>(row, col);
      if (!(d > 0) || !std::isfinite(d)) continue;
      ++image->statistics.num_with_depth;
      if (!(t > 0) || !std::isfinite(t)) continue;
      const double error = static_cast<double>(d) - t;
      image->absolute.Add(std::abs(error));
      image->relative.Add(std::abs(error) / t);
      image->signed_sum += error;
      if (image->statistics.num_compared++ % sample_stride == 0) sample->push_back(std::abs(error));
    }
  }
}

}  // namespace

DenseDepthEvaluation EvaluateDenseDepth(const std::string& dense_path,
                                        const std::string& true_depth_path) {
  // fusion.cfg first: the workspace's constructor creates its folders.
  const std::vector<std::string> names = ReadFusionImageNames(dense_path);
  const DenseWorkspace workspace(dense_path);
  DenseDepthEvaluation evaluation;
  Accumulator all;
  for (const std::string& name : names) {
    const fs::path truth_file =
        fs::path(true_depth_path) / (fs::path(name).stem().string() + ".bin");
    if (!fs::is_regular_file(truth_file)) {
      evaluation.images_without_truth.push_back(name);
      continue;
    }
    const cv::Mat dense = workspace.ReadDepthMap(name);
    const cv::Mat truth = ReadColmapDepthMap(truth_file.string());
    if (truth.size() != dense.size()) {
      evaluation.images_of_another_size.push_back(name);
      continue;
    }
    // About a million samples over the whole model.
    const size_t stride = std::max<size_t>(1, dense.total() * names.size() / 1000000);
    Accumulator image;
    CompareImage(dense, truth, stride, &image, &evaluation.abs_error_sample);
    evaluation.image_names.push_back(name);
    evaluation.per_image.push_back(image.Finish());
    all.Merge(image);
  }
  evaluation.all = all.Finish();
  return evaluation;
}

}  // namespace colmap_lidar
