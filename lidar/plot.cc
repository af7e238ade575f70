#include "lidar/plot.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

std::string Format(double value) {
  std::ostringstream out;
  out << std::setprecision(3) << value;
  return out.str();
}

}  // namespace

Color3ub ErrorColor(double value, double max_value) {
  const double t =
      std::clamp(max_value > 0 ? value / max_value : 0.0, 0.0, 1.0);
  // Piecewise linear: blue (0) -> cyan -> green -> yellow -> red (1).
  const double r = std::clamp(4 * t - 2, 0.0, 1.0);
  const double g =
      t < 0.75 ? std::clamp(4 * t, 0.0, 1.0) : std::clamp(4 - 4 * t, 0.0, 1.0);
  const double b = std::clamp(2 - 4 * t, 0.0, 1.0);
  return Color3ub(static_cast<uint8_t>(255 * r),
                  static_cast<uint8_t>(255 * g),
                  static_cast<uint8_t>(255 * b));
}

void WriteHistogramPng(const std::string& path,
                       const std::vector<double>& values,
                       const HistogramPlotOptions& options) {
  constexpr int kWidth = 800, kHeight = 500, kLeft = 70, kRight = 45, kTop = 50,
                kBottom = 60;
  cv::Mat canvas(kHeight, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  double max_value = options.max_value;
  if (max_value <= 0 && !values.empty()) {
    std::vector<double> sorted = values;
    const size_t k = static_cast<size_t>(0.99 * (sorted.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
    max_value = sorted[k];
  }
  if (max_value <= 0)
    max_value = 1.0 / options.value_scale;  // one unit on the axis
  const int bins = std::max(1, options.num_bins);
  std::vector<int> counts(bins, 0);
  for (double v : values) {
    counts[std::clamp(static_cast<int>(v / max_value * bins), 0, bins - 1)]++;
  }
  const int max_count =
      std::max(1, *std::max_element(counts.begin(), counts.end()));
  const int plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  for (int b = 0; b < bins; ++b) {
    const int x0 = kLeft + b * plot_w / bins,
              x1 = kLeft + (b + 1) * plot_w / bins - 1;
    const int h = counts[b] * plot_h / max_count;
    const Color3ub c = ErrorColor(b + 0.5, bins);
    cv::rectangle(canvas,
                  cv::Point(x0, kTop + plot_h - h),
                  cv::Point(x1, kTop + plot_h),
                  cv::Scalar(c[2], c[1], c[0]),
                  cv::FILLED);
  }
  const cv::Scalar black(0, 0, 0);
  cv::line(
      canvas, {kLeft, kTop + plot_h}, {kLeft + plot_w, kTop + plot_h}, black);
  cv::line(canvas, {kLeft, kTop}, {kLeft, kTop + plot_h}, black);
  for (int tick = 0; tick <= 5; ++tick) {
    const int x = kLeft + tick * plot_w / 5;
    cv::line(canvas, {x, kTop + plot_h}, {x, kTop + plot_h + 5}, black);
    cv::putText(canvas,
                Format(tick * max_value * options.value_scale / 5),
                {x - 15, kTop + plot_h + 22},
                cv::FONT_HERSHEY_SIMPLEX,
                0.45,
                black);
  }
  cv::putText(canvas,
              Format(max_count),
              {5, kTop + 10},
              cv::FONT_HERSHEY_SIMPLEX,
              0.45,
              black);
  cv::putText(canvas,
              options.title + "  (n = " + std::to_string(values.size()) + ")",
              {kLeft, 30},
              cv::FONT_HERSHEY_SIMPLEX,
              0.6,
              black,
              1,
              cv::LINE_AA);
  cv::putText(canvas,
              options.x_label,
              {kLeft + plot_w / 2 - 60, kHeight - 12},
              cv::FONT_HERSHEY_SIMPLEX,
              0.5,
              black,
              1,
              cv::LINE_AA);
  const std::string tmp = path + ".tmp" + std::to_string(::getpid()) + ".png";
  if (!cv::imwrite(tmp, canvas))
    throw std::runtime_error("Cannot write plot " + path);
  std::filesystem::rename(tmp, path);
}

}  // namespace colmap_lidar
