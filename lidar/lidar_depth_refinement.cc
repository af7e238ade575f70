#include "lidar/lidar_depth_refinement.h"

#include "lidar/util/check_option.h"
#include "lidar/util/statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace colmap_lidar {
namespace {

using IndexImage = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

double DegToRad(double degrees) { return degrees * M_PI / 180; }

// Projected centre of every sample (NaN behind the camera).
std::vector<Eigen::Vector2d> ProjectSamples(const LidarSurface& surface,
                                            const PinholeIntrinsics& intrinsics) {
  std::vector<Eigen::Vector2d> xy(
      surface.Size(), Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (size_t i = 0; i < surface.Size(); ++i) {
    intrinsics.Project(surface.points[i], &xy[i]);
  }
  return xy;
}

IndexImage Splat(const LidarSurface& surface,
                 const std::vector<Eigen::Vector2d>& xy,
                 const PinholeIntrinsics& intrinsics,
                 int max_radius_px) {
  IndexImage index = IndexImage::Constant(intrinsics.height, intrinsics.width, -1);
  DepthImage zbuffer = DepthImage::Constant(
      intrinsics.height, intrinsics.width, std::numeric_limits<float>::infinity());
  for (size_t i = 0; i < surface.Size(); ++i) {
    if (!std::isfinite(xy[i].x())) continue;
    const double z = surface.points[i].z();
    const int radius = std::min(
        max_radius_px, static_cast<int>(0.5 * surface.spacing[i] * intrinsics.fx / z + 0.5));
    const int col0 = static_cast<int>(std::floor(xy[i].x()));
    const int row0 = static_cast<int>(std::floor(xy[i].y()));
    for (int row = std::max(0, row0 - radius);
         row <= std::min(intrinsics.height - 1, row0 + radius);
         ++row) {
      for (int col = std::max(0, col0 - radius);
           col <= std::min(intrinsics.width - 1, col0 + radius);
           ++col) {
        if ((row - row0) * (row - row0) + (col - col0) * (col - col0) > radius * radius) {
          continue;
        }
        if (z < zbuffer(row, col)) {
          zbuffer(row, col) = float(z);
          index(row, col) = static_cast<int>(i);
        }
      }
    }
  }
  return index;
}

enum class FillVerdict { kFill, kNoLayer, kEdge, kSparse, kViewAngle, kCurvature };

int AutomaticWindowRadius(const LidarSurface& surface,
                          const std::vector<Eigen::Vector2d>& xy,
                          const PinholeIntrinsics& intrinsics) {
  std::vector<double> spacing_px;
  for (size_t i = 0; i < surface.Size(); ++i) {
    if (std::isfinite(xy[i].x()) && intrinsics.Contains(xy[i])) {
      spacing_px.push_back(surface.spacing[i] * intrinsics.fx / surface.points[i].z());
    }
  }
  if (spacing_px.empty()) return 3;
  return std::clamp(static_cast<int>(std::lround(1.5 * Median(std::move(spacing_px)))), 3, 30);
}

// The visible samples (those owning a pixel of the z-buffer), bucketed in square cells of the window
// radius: a pixel's window is gathered from 3 x 3 cells, not from (2 radius + 1)^2 pixels, which at
// 12 MP and a 30 px window would be thousands of lookups per pixel.
class SampleGrid {
 public:
  SampleGrid(const std::vector<Eigen::Vector2d>& xy,
             const IndexImage& index,
             int radius,
             int width,
             int height)
      : xy_(xy),
        index_(index),
        radius_(radius),
        cells_x_((width + radius - 1) / radius),
        cells_y_((height + radius - 1) / radius) {
    std::vector<uint8_t> visible(xy.size(), 0);
    for (Eigen::Index k = 0; k < index.size(); ++k) {
      if (index.data()[k] >= 0) visible[index.data()[k]] = 1;
    }
    cell_start_.assign(size_t(cells_x_) * cells_y_ + 1, 0);
    for (size_t s = 0; s < xy.size(); ++s) {
      if (visible[s]) ++cell_start_[CellOf(xy[s]) + 1];
    }
    for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
    cell_samples_.resize(cell_start_.back());
    std::vector<int> fill = cell_start_;
    for (size_t s = 0; s < xy.size(); ++s) {
      if (visible[s]) cell_samples_[fill[CellOf(xy[s])]++] = int(s);
    }
  }

  // The visible samples whose projection lies within the radius of the pixel's centre, and the
  // sample owning the pixel (a splat may reach it from farther away).
  void Window(int col, int row, std::vector<int>* window) const {
    window->clear();
    const Eigen::Vector2d centre(col + 0.5, row + 0.5);
    const int cell_x = col / radius_, cell_y = row / radius_;
    for (int cy = std::max(0, cell_y - 1); cy <= std::min(cells_y_ - 1, cell_y + 1); ++cy) {
      for (int cx = std::max(0, cell_x - 1); cx <= std::min(cells_x_ - 1, cell_x + 1); ++cx) {
        const size_t c = size_t(cy) * cells_x_ + cx;
        for (int k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
          const int s = cell_samples_[k];
          if ((xy_[s] - centre).squaredNorm() <= double(radius_) * radius_) window->push_back(s);
        }
      }
    }
    const int owner = index_(row, col);
    if (owner >= 0 && std::find(window->begin(), window->end(), owner) == window->end()) {
      window->push_back(owner);
    }
  }

 private:
  size_t CellOf(const Eigen::Vector2d& xy) const {  // visible samples may lie just outside
    const int cx = std::clamp(static_cast<int>(std::floor(xy.x())) / radius_, 0, cells_x_ - 1);
    const int cy = std::clamp(static_cast<int>(std::floor(xy.y())) / radius_, 0, cells_y_ - 1);
    return size_t(cy) * cells_x_ + cx;
  }

  const std::vector<Eigen::Vector2d>& xy_;
  const IndexImage& index_;
  const int radius_, cells_x_, cells_y_;
  std::vector<int> cell_start_;
  std::vector<int> cell_samples_;
};

// The LiDAR layer at a pixel: the window's samples on the plane of the sample nearest the pixel.
struct Layer {
  std::vector<int> samples;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double plane_offset = 0;  // n . x on the layer's plane
  double curvature = 0;     // the largest of its samples
  bool has_plane = false;   // the plane is seen at less than 85 deg and in front of the camera
  double lidar_z = 0;       // the plane's depth along the pixel's ray
};

// One pixel's window: the visible samples around it, the sample owning the pixel (-1: none), the
// pixel's centre and its ray (z = 1).
struct PixelWindow {
  const std::vector<int>& window;
  int owner;
  Eigen::Vector2d centre;
  Eigen::Vector3d ray;
};

// The layer of the window's samples on the plane of the sample nearest the pixel (within
// plane_tolerance_m of it, normals within the angle whose cosine is min_normal_cos).
void FitLayer(const LidarSurface& surface,
              const std::vector<Eigen::Vector2d>& xy,
              const PixelWindow& pixel,
              double min_normal_cos,
              double plane_tolerance_m,
              Layer* layer) {
  const std::vector<int>& window = pixel.window;
  layer->samples.clear();
  layer->has_plane = false;
  layer->curvature = 0;
  if (window.empty()) return;
  int nearest = pixel.owner;
  if (nearest < 0) {
    double best = std::numeric_limits<double>::infinity();
    for (int s : window) {
      const double d = (xy[s] - pixel.centre).squaredNorm();
      if (d < best) best = d, nearest = s;
    }
  }
  const Eigen::Vector3d& n0 = surface.normals[nearest];
  const Eigen::Vector3d& x0 = surface.points[nearest];
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int s : window) {
    if (std::abs(n0.dot(surface.points[s] - x0)) <= plane_tolerance_m &&
        n0.dot(surface.normals[s]) >= min_normal_cos) {
      layer->samples.push_back(s);
      normal_sum += surface.normals[s];
      centroid += surface.points[s];
      layer->curvature = std::max(layer->curvature, double(surface.curvature[s]));
    }
  }
  layer->normal = normal_sum.normalized();
  centroid /= double(layer->samples.size());
  layer->plane_offset = layer->normal.dot(centroid);
  static const double kMinRayCos = std::cos(DegToRad(85));
  if (std::abs(layer->normal.dot(pixel.ray.normalized())) > kMinRayCos) {
    layer->lidar_z = layer->plane_offset / layer->normal.dot(pixel.ray);
    layer->has_plane = layer->lidar_z > 0;
  }
}

// Fold 2's verdict at one pixel (paper, mapping step (2)): fill only inside one flat,
// well-observed LiDAR layer that surrounds the pixel. With a second surface in the window (a depth
// edge or a crease) the layer must surround the pixel on all four sides: a pixel beyond the layer's
// border, on the other surface, never has layer samples on the other surface's side.
FillVerdict JudgeFill(const Layer& layer,
                      const PixelWindow& pixel,
                      const std::vector<Eigen::Vector2d>& xy,
                      double min_view_cos,
                      const LidarDepthRefinementOptions& options) {
  if (static_cast<int>(layer.samples.size()) < options.min_fill_samples) {
    return FillVerdict::kSparse;
  }
  if (std::abs(layer.normal.dot(pixel.ray.normalized())) < min_view_cos) {
    return FillVerdict::kViewAngle;
  }
  int quadrants = 0;
  for (int s : layer.samples) {
    const Eigen::Vector2d d = xy[s] - pixel.centre;
    if (d.squaredNorm() < 0.25) {
      quadrants = 0xF;
    } else {
      quadrants |= 1 << (d.x() >= 0 ? (d.y() >= 0 ? 0 : 3) : (d.y() >= 0 ? 1 : 2));
    }
  }
  int num_quadrants = 0;
  for (int q = 0; q < 4; ++q) num_quadrants += (quadrants >> q) & 1;
  if (layer.samples.size() != pixel.window.size() && num_quadrants < 4) {
    return FillVerdict::kEdge;
  }
  if (num_quadrants < options.min_fill_quadrants) return FillVerdict::kSparse;
  if (layer.curvature > options.max_fill_curvature) {
    return FillVerdict::kCurvature;
  }
  return FillVerdict::kFill;
}

void AddStats(const LidarDepthRefinementStats& local, LidarDepthRefinementStats* stats) {
  stats->stereo_pixels += local.stereo_pixels;
  stats->stereo_without_lidar += local.stereo_without_lidar;
  stats->stereo_confirmed += local.stereo_confirmed;
  stats->stereo_removed += local.stereo_removed;
  stats->filled += local.filled;
  stats->fill_refused_edge += local.fill_refused_edge;
  stats->fill_refused_sparse += local.fill_refused_sparse;
  stats->fill_refused_view_angle += local.fill_refused_view_angle;
  stats->fill_refused_curvature += local.fill_refused_curvature;
}

void CheckDepthMapSize(const DepthImage& stereo, const PinholeIntrinsics& intrinsics) {
  ThrowUnlessValid(intrinsics, "PinholeIntrinsics");
  if (stereo.rows() != intrinsics.height || stereo.cols() != intrinsics.width) {
    throw std::invalid_argument(
        "RefineDepthWithLidar: the depth map is " + std::to_string(stereo.cols()) + "x" +
        std::to_string(stereo.rows()) + " but the camera is " + std::to_string(intrinsics.width) +
        "x" + std::to_string(intrinsics.height));
  }
}

// The result at one pixel.
struct PixelDepth {
  float depth = 0;
  DepthSource source = DepthSource::kNone;
  bool lidar_normal = false;  // the layer's normal applies
};

// Fold 1 (paper, mapping step (1)) on a stereo pixel. Disagreement is the stereo point's distance to
// the LiDAR plane (what the model's accuracy is measured by), not the depth difference along the
// ray, which an obliquely seen plane magnifies by 1 / cos(view angle).
PixelDepth JudgeStereo(float stereo_z,
                       const Eigen::Vector3d& ray,
                       const Layer& layer,
                       FillVerdict verdict,
                       const LidarDepthRefinementOptions& options,
                       LidarDepthRefinementStats* stats) {
  const double distance = std::abs(layer.normal.dot(ray * double(stereo_z)) - layer.plane_offset);
  const bool flat_layer = layer.has_plane && layer.curvature <= options.max_check_curvature;
  const bool replaceable = verdict == FillVerdict::kFill;
  const double agreement = options.max_abs_diff_m + options.max_rel_diff * layer.lidar_z;
  const double tolerance = replaceable ? agreement : options.max_unreplaceable_diff_m;
  if (!flat_layer || !options.remove_inconsistent) {
    ++stats->stereo_without_lidar;  // kept, not judged
    return {stereo_z, DepthSource::kStereo, false};
  }
  if (distance <= tolerance) {
    if (distance <= agreement) {
      ++stats->stereo_confirmed;
      return {stereo_z, DepthSource::kStereo, true};
    }
    ++stats->stereo_without_lidar;  // off, but nothing better to put there
    return {stereo_z, DepthSource::kStereo, false};
  }
  ++stats->stereo_removed;
  if (!replaceable) return {0, DepthSource::kRemoved, false};
  ++stats->filled;
  return {float(layer.lidar_z), DepthSource::kLidar, true};
}

// Fold 2 on a pixel without stereo depth: filled from the layer, or counted by why not.
PixelDepth FillHole(const Layer& layer, FillVerdict verdict, LidarDepthRefinementStats* stats) {
  switch (verdict) {
    case FillVerdict::kFill:
      ++stats->filled;
      return {float(layer.lidar_z), DepthSource::kLidar, true};
    case FillVerdict::kEdge:
      ++stats->fill_refused_edge;
      break;
    case FillVerdict::kSparse:
      ++stats->fill_refused_sparse;
      break;
    case FillVerdict::kViewAngle:
      ++stats->fill_refused_view_angle;
      break;
    case FillVerdict::kCurvature:
      ++stats->fill_refused_curvature;
      break;
    case FillVerdict::kNoLayer:
      break;
  }
  return {};
}

// What every pixel's refinement reads.
struct PixelContext {
  const DepthImage& stereo;
  const LidarSurface& surface;
  const PinholeIntrinsics& intrinsics;
  const LidarDepthRefinementOptions& options;
  const std::vector<Eigen::Vector2d>& xy;  // the samples' image positions
  const IndexImage& index;
  const SampleGrid& grid;
  double min_normal_cos;
  double min_view_cos;
};

// One pixel: the LiDAR layer of its window (`window`, `layer`: scratch), then its stereo depth
// checked against the layer (fold 1) or its hole filled from it (fold 2).
PixelDepth RefinePixel(const PixelContext& c,
                       int row,
                       int col,
                       std::vector<int>* window,
                       Layer* layer,
                       LidarDepthRefinementStats* stats) {
  const float stereo_z = c.stereo(row, col);
  const bool has_stereo = stereo_z > 0 && std::isfinite(stereo_z);
  stats->stereo_pixels += has_stereo;
  c.grid.Window(col, row, window);
  const PixelWindow pixel{*window,
                          c.index(row, col),
                          Eigen::Vector2d(col + 0.5, row + 0.5),
                          c.intrinsics.PixelRay(col, row)};
  FitLayer(c.surface, c.xy, pixel, c.min_normal_cos, c.options.plane_tolerance_m, layer);
  const FillVerdict verdict = layer->has_plane && c.options.fill_holes
                                  ? JudgeFill(*layer, pixel, c.xy, c.min_view_cos, c.options)
                                  : FillVerdict::kNoLayer;
  return has_stereo ? JudgeStereo(stereo_z, pixel.ray, *layer, verdict, c.options, stats)
                    : FillHole(*layer, verdict, stats);
}

}  // namespace

bool LidarDepthRefinementOptions::Check() const {
  LIDAR_CHECK_OPTION_GE(window_radius_px, 0);  // 0: automatic
  LIDAR_CHECK_OPTION_GE(max_abs_diff_m, 0);
  LIDAR_CHECK_OPTION_GE(max_rel_diff, 0);
  LIDAR_CHECK_OPTION_GE(max_check_curvature, 0);
  LIDAR_CHECK_OPTION_GE(max_unreplaceable_diff_m, max_abs_diff_m);
  LIDAR_CHECK_OPTION_GT(plane_tolerance_m, 0);
  LIDAR_CHECK_OPTION(max_normal_angle_deg > 0 && max_normal_angle_deg < 90);
  LIDAR_CHECK_OPTION_GE(min_fill_samples, 1);
  LIDAR_CHECK_OPTION(min_fill_quadrants >= 0 && min_fill_quadrants <= 4);
  LIDAR_CHECK_OPTION_GE(max_fill_curvature, 0);
  LIDAR_CHECK_OPTION(max_fill_view_angle_deg > 0 && max_fill_view_angle_deg < 90);
  return true;
}

RefinedDepth RefineDepthWithLidar(const DepthImage& stereo,
                                  const LidarSurface& surface,
                                  const PinholeIntrinsics& intrinsics,
                                  const LidarDepthRefinementOptions& options) {
  ThrowUnlessValid(options, "LidarDepthRefinementOptions");
  CheckDepthMapSize(stereo, intrinsics);
  const int width = intrinsics.width;
  const int height = intrinsics.height;
  const std::vector<Eigen::Vector2d> xy = ProjectSamples(surface, intrinsics);
  const int radius = options.window_radius_px > 0 ? options.window_radius_px
                                                  : AutomaticWindowRadius(surface, xy, intrinsics);
  // Footprints reach at most half the window: a sample never hides a whole window.
  const IndexImage index = Splat(surface, xy, intrinsics, std::max(1, radius / 2));
  const SampleGrid grid(xy, index, radius, width, height);
  const PixelContext context{stereo,
                             surface,
                             intrinsics,
                             options,
                             xy,
                             index,
                             grid,
                             std::cos(DegToRad(options.max_normal_angle_deg)),
                             std::cos(DegToRad(options.max_fill_view_angle_deg))};

  RefinedDepth result;
  result.depth = DepthImage::Zero(height, width);
  result.normals = NormalImage(width, height);
  result.source.assign(size_t(width) * height, DepthSource::kNone);
#pragma omp parallel
  {
    LidarDepthRefinementStats local;
    std::vector<int> window;
    Layer layer;
#pragma omp for schedule(dynamic, 8)
    for (int row = 0; row < height; ++row) {
      for (int col = 0; col < width; ++col) {
        const PixelDepth pixel = RefinePixel(context, row, col, &window, &layer, &local);
        const size_t k = size_t(row) * width + col;
        result.depth(row, col) = pixel.depth;
        result.source[k] = pixel.source;
        if (pixel.lidar_normal) result.normals.normals[k] = layer.normal.cast<float>();
      }
    }
#pragma omp critical
    AddStats(local, &result.stats);
  }

  // Stereo pixels without a LiDAR layer take their normal from the depth map.
  const NormalImage from_depth = NormalsFromDepth(result.depth, intrinsics);
  for (size_t pixel = 0; pixel < result.source.size(); ++pixel) {
    if (result.depth.data()[pixel] > 0 && result.normals.normals[pixel].isZero()) {
      result.normals.normals[pixel] = from_depth.normals[pixel];
    }
  }
  result.stats.window_radius_px = radius;
  return result;
}

}  // namespace colmap_lidar
