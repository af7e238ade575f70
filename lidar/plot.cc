#include "lidar/plot.h"

#include "lidar/util/atomic_file.h"
#include "lidar/util/statistics.h"

#include <Eigen/Eigenvalues>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

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

void PutText(cv::Mat* canvas, const std::string& text, const cv::Point& origin, double scale) {
  cv::putText(
      *canvas, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
}

void WritePngAtomically(const std::string& path, const cv::Mat& canvas) {
  WriteAtomically(
      path, [&canvas](const std::string& temporary) { return cv::imwrite(temporary, canvas); });
}

}  // namespace

namespace {

constexpr int kLineWidth = 800, kLineHeight = 500, kLineLeft = 80, kLineRight = 150, kLineTop = 50,
              kLineBottom = 60;
constexpr int kLinePlotW = kLineWidth - kLineLeft - kLineRight;
constexpr int kLinePlotH = kLineHeight - kLineTop - kLineBottom;

// The data's extent on the plot's axes (y in log10 with log_y; non-positive y then left out),
// widened to 2 where it is a point.
struct LinePlotRange {
  bool log_y = false;
  double x_min = INFINITY, x_max = -INFINITY, y_min = INFINITY, y_max = -INFINITY;

  double Y(double y) const { return log_y ? std::log10(y) : y; }
  cv::Point Pixel(double x, double y) const {
    return cv::Point(
        kLineLeft + static_cast<int>((x - x_min) / (x_max - x_min) * kLinePlotW),
        kLineTop + kLinePlotH - static_cast<int>((Y(y) - y_min) / (y_max - y_min) * kLinePlotH));
  }
};

LinePlotRange RangeOf(const std::vector<PlotSeries>& series, bool log_y) {
  LinePlotRange range;
  range.log_y = log_y;
  for (const PlotSeries& s : series) {
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (log_y && s.y[i] <= 0) continue;
      range.x_min = std::min(range.x_min, s.x[i]);
      range.x_max = std::max(range.x_max, s.x[i]);
      range.y_min = std::min(range.y_min, range.Y(s.y[i]));
      range.y_max = std::max(range.y_max, range.Y(s.y[i]));
    }
  }
  if (!(range.x_max > range.x_min)) {
    range.x_min = std::isfinite(range.x_min) ? range.x_min - 1 : 0;
    range.x_max = range.x_min + 2;
  }
  if (!(range.y_max > range.y_min)) {
    range.y_min = std::isfinite(range.y_min) ? range.y_min - 1 : 0;
    range.y_max = range.y_min + 2;
  }
  return range;
}

// The frame and six ticks per axis.
void DrawLinePlotAxes(const LinePlotRange& range, cv::Mat* canvas) {
  const cv::Scalar black(0, 0, 0);
  cv::rectangle(
      *canvas, {kLineLeft, kLineTop}, {kLineLeft + kLinePlotW, kLineTop + kLinePlotH}, black);
  for (int tick = 0; tick <= 5; ++tick) {
    const int x = kLineLeft + tick * kLinePlotW / 5;
    const int y = kLineTop + kLinePlotH - tick * kLinePlotH / 5;
    cv::putText(*canvas,
                Format(range.x_min + tick * (range.x_max - range.x_min) / 5),
                {x - 15, kLineTop + kLinePlotH + 22},
                cv::FONT_HERSHEY_SIMPLEX,
                0.45,
                black);
    const double y_tick = range.y_min + tick * (range.y_max - range.y_min) / 5;
    cv::putText(*canvas,
                Format(range.log_y ? std::pow(10, y_tick) : y_tick),
                {5, y + 5},
                cv::FONT_HERSHEY_SIMPLEX,
                0.45,
                black);
  }
}

// Series k of `num_series` as a line with dots, and its legend entry.
void DrawLineSeries(
    const PlotSeries& s, size_t k, size_t num_series, const LinePlotRange& range, cv::Mat* canvas) {
  const Color3ub c = ErrorColor(static_cast<double>(k), std::max<double>(1, num_series - 1));
  const cv::Scalar colour(0.8 * c[2], 0.8 * c[1], 0.8 * c[0]);
  bool has_previous = false;
  cv::Point previous;
  for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
    if (range.log_y && s.y[i] <= 0) continue;
    const cv::Point p = range.Pixel(s.x[i], s.y[i]);
    if (has_previous) cv::line(*canvas, previous, p, colour, 2, cv::LINE_AA);
    cv::circle(*canvas, p, 2, colour, cv::FILLED);
    previous = p;
    has_previous = true;
  }
  const int legend_y = kLineTop + 15 + 22 * static_cast<int>(k);
  cv::line(*canvas,
           {kLineLeft + kLinePlotW + 10, legend_y - 4},
           {kLineLeft + kLinePlotW + 35, legend_y - 4},
           colour,
           2);
  PutText(canvas, s.label, {kLineLeft + kLinePlotW + 40, legend_y}, 0.45);
}

}  // namespace

void WriteLinePlotPng(const std::string& path,
                      const std::vector<PlotSeries>& series,
                      const LinePlotOptions& options) {
  cv::Mat canvas(kLineHeight, kLineWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  const LinePlotRange range = RangeOf(series, options.log_y);
  DrawLinePlotAxes(range, &canvas);
  for (size_t k = 0; k < series.size(); ++k) {
    DrawLineSeries(series[k], k, series.size(), range, &canvas);
  }
  PutText(&canvas, options.title, {kLineLeft, 30}, 0.6);
  PutText(&canvas, options.x_label, {kLineLeft + kLinePlotW / 2 - 60, kLineHeight - 12}, 0.5);
  PutText(&canvas, options.y_label + (options.log_y ? " (log)" : ""), {5, kLineTop - 10}, 0.45);
  WritePngAtomically(path, canvas);
}

namespace {

// The reference's centroid and its two axes of largest spread (a drive's ground plane).
struct PlotFrame {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d axis_v = Eigen::Vector3d::UnitY();
};

PlotFrame PrincipalPlane(const std::vector<Eigen::Vector3d>& points) {
  PlotFrame frame;
  if (points.empty()) return frame;
  for (const Eigen::Vector3d& p : points) frame.centre += p / static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points)
    scatter += (p - frame.centre) * (p - frame.centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  frame.axis_u = solver.eigenvectors().col(2);
  frame.axis_v = solver.eigenvectors().col(1);
  return frame;
}

void DrawColourBar(cv::Mat* canvas,
                   const cv::Rect& box,
                   double max_value,
                   const std::string& label) {
  for (int y = 0; y < box.height; ++y) {
    const Color3ub c = ErrorColor(box.height - 1 - y, box.height - 1);
    cv::line(
        *canvas, {box.x, box.y + y}, {box.x + box.width, box.y + y}, cv::Scalar(c[2], c[1], c[0]));
  }
  PutText(canvas, Format(max_value), {box.x + box.width + 5, box.y + 10}, 0.45);
  PutText(canvas, "0", {box.x + box.width + 5, box.y + box.height}, 0.45);
  PutText(canvas, label, {box.x - 40, box.y - 10}, 0.45);
}

}  // namespace

void WriteTopViewPng(const std::string& path,
                     const std::vector<Eigen::Vector3d>& reference,
                     const std::vector<Eigen::Vector3d>& estimate,
                     const std::vector<double>& values,
                     const TopViewPlotOptions& options) {
  constexpr int kWidth = 900, kHeight = 700, kMargin = 60, kBar = 120;
  cv::Mat canvas(kHeight, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  const PlotFrame frame = PrincipalPlane(reference);
  const auto plane = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d((p - frame.centre).dot(frame.axis_u),
                           (p - frame.centre).dot(frame.axis_v));
  };
  Eigen::AlignedBox2d box;
  for (const auto* points : {&reference, &estimate}) {
    for (const Eigen::Vector3d& p : *points) box.extend(plane(p));
  }
  const double span = std::max({box.sizes().x(), box.sizes().y(), 1e-6});
  const double scale = std::min(kWidth - 2 * kMargin - kBar, kHeight - 2 * kMargin) / span;
  // The paths' box centred in the drawing area.
  const Eigen::Vector2d area(kWidth - 2 * kMargin - kBar, kHeight - 2 * kMargin);
  const Eigen::Vector2d offset = 0.5 * (area - box.sizes() * scale);
  const auto pixel = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d q = (plane(p) - box.min()) * scale + offset;
    return cv::Point(kMargin + static_cast<int>(q.x()),
                     kHeight - kMargin - static_cast<int>(q.y()));
  };
  for (size_t k = 1; k < reference.size(); ++k) {
    cv::line(canvas,
             pixel(reference[k - 1]),
             pixel(reference[k]),
             cv::Scalar(150, 150, 150),
             3,
             cv::LINE_AA);
  }
  const double max_value =
      values.empty() ? 1.0 : std::max(*std::max_element(values.begin(), values.end()), 1e-12);
  for (size_t k = 0; k < estimate.size(); ++k) {
    const Color3ub c = ErrorColor(k < values.size() ? values[k] : 0.0, max_value);
    cv::circle(
        canvas, pixel(estimate[k]), 4, cv::Scalar(c[2], c[1], c[0]), cv::FILLED, cv::LINE_AA);
  }
  DrawColourBar(&canvas,
                cv::Rect(kWidth - kBar + 20, kMargin + 20, 20, kHeight - 2 * kMargin - 40),
                max_value * options.value_scale,
                options.value_label);
  PutText(&canvas, options.title, {kMargin, 30}, 0.6);
  PutText(&canvas,
          "grey: reference; points: estimate; the view spans " + Format(span) + " m",
          {kMargin, kHeight - 20},
          0.45);
  WritePngAtomically(path, canvas);
}

Color3ub ErrorColor(double value, double max_value) {
  const double t = std::clamp(max_value > 0 ? value / max_value : 0.0, 0.0, 1.0);
  // Piecewise linear: blue (0) -> cyan -> green -> yellow -> red (1).
  const double r = std::clamp(4 * t - 2, 0.0, 1.0);
  const double g = t < 0.75 ? std::clamp(4 * t, 0.0, 1.0) : std::clamp(4 - 4 * t, 0.0, 1.0);
  const double b = std::clamp(2 - 4 * t, 0.0, 1.0);
  return Color3ub(
      static_cast<uint8_t>(255 * r), static_cast<uint8_t>(255 * g), static_cast<uint8_t>(255 * b));
}

void WriteHistogramPng(const std::string& path,
                       const std::vector<double>& values,
                       const HistogramPlotOptions& options) {
  constexpr int kWidth = 800, kHeight = 500, kLeft = 70, kRight = 45, kTop = 50, kBottom = 60;
  cv::Mat canvas(kHeight, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  double max_value = options.max_value;
  if (max_value <= 0 && !values.empty()) {
    max_value = Quantile(values, 0.99);
  }
  if (max_value <= 0) max_value = 1.0 / options.value_scale;  // one unit on the axis
  const int bins = std::max(1, options.num_bins);
  std::vector<int> counts(bins, 0);
  for (double v : values) {
    counts[std::clamp(static_cast<int>(v / max_value * bins), 0, bins - 1)]++;
  }
  const int max_count = std::max(1, *std::max_element(counts.begin(), counts.end()));
  const int plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  for (int b = 0; b < bins; ++b) {
    const int x0 = kLeft + b * plot_w / bins, x1 = kLeft + (b + 1) * plot_w / bins - 1;
    const int h = counts[b] * plot_h / max_count;
    const Color3ub c = ErrorColor(b + 0.5, bins);
    cv::rectangle(canvas,
                  cv::Point(x0, kTop + plot_h - h),
                  cv::Point(x1, kTop + plot_h),
                  cv::Scalar(c[2], c[1], c[0]),
                  cv::FILLED);
  }
  const cv::Scalar black(0, 0, 0);
  cv::line(canvas, {kLeft, kTop + plot_h}, {kLeft + plot_w, kTop + plot_h}, black);
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
  cv::putText(canvas, Format(max_count), {5, kTop + 10}, cv::FONT_HERSHEY_SIMPLEX, 0.45, black);
  PutText(
      &canvas, options.title + "  (n = " + std::to_string(values.size()) + ")", {kLeft, 30}, 0.6);
  PutText(&canvas, options.x_label, {kLeft + plot_w / 2 - 60, kHeight - 12}, 0.5);
  WritePngAtomically(path, canvas);
}

}  // namespace colmap_lidar
