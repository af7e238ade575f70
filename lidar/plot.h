// Small PNG plots for reports (OpenCV inside): people look at results.
#pragma once

#include "lidar/point_cloud.h"

#include <string>
#include <vector>

namespace colmap_lidar {

struct HistogramPlotOptions {
  std::string title;
  std::string x_label;
  // values are multiplied by this for the axis (e.g. 1000 for mm)
  double value_scale = 1.0;
  // upper end of the axis in input units; 0 = 99th percentile
  double max_value = 0;
  int num_bins = 50;
};

// Writes a histogram PNG (atomically). Throws std::runtime_error if it cannot be written.
void WriteHistogramPng(const std::string& path,
                       const std::vector<double>& values,
                       const HistogramPlotOptions& options);

struct PlotSeries {
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
};

struct LinePlotOptions {
  std::string title;
  std::string x_label;
  std::string y_label;
  // log10 axis for y (values <= 0 are skipped)
  bool log_y = false;
};

// Writes a line plot PNG of one or more series with a legend (atomically).
void WriteLinePlotPng(const std::string& path,
                      const std::vector<PlotSeries>& series,
                      const LinePlotOptions& options);

struct TopViewPlotOptions {
  std::string title;
  std::string value_label;  // of the colour bar, e.g. "step error [cm]"
  double value_scale = 1;   // values are multiplied by this for the colour bar's labels
};

// Writes a top view of two paths (atomically): the plane of the two largest spreads of the
// reference's positions, equal scales on both axes; the reference in grey, the estimate as points
// coloured by `values` (one per estimated position; ErrorColor from 0 to their maximum) with a
// colour bar.
void WriteTopViewPng(const std::string& path,
                     const std::vector<Eigen::Vector3d>& reference,
                     const std::vector<Eigen::Vector3d>& estimate,
                     const std::vector<double>& values,
                     const TopViewPlotOptions& options);

// A blue-green-yellow-red colour for value/max_value in [0, 1] (clamped).
Color3ub ErrorColor(double value, double max_value);

}  // namespace colmap_lidar
