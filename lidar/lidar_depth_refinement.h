// LiDAR-guided refinement of one station's stereo depth map (the paper's mapping step):
//   fold 1  stereo depths whose points lie off the local LiDAR surface are removed (and replaced by
//           the LiDAR depth where fold 2 allows one);
//   fold 2  holes are filled from the LiDAR surface where it is flat (low curvature), well observed
//           (small angle between its normal and the viewing ray) and surrounds the pixel (on all four
//           sides when another surface is near: never across a depth edge), by intersecting the
//           pixel's ray with the local plane.
//
// The local LiDAR surface at a pixel: the LiDAR surface samples (lidar_surface.h) are splatted into a
// z-buffer, each over its footprint (half its spacing, in pixels), so that a sample hidden behind a
// nearer surface from the camera's viewpoint (LiDAR and camera see from different places) is not used.
// The visible samples projecting within `window_radius_px` of the pixel form the window; the visible sample nearest the pixel defines
// the layer: the window samples on its plane (distance and normal agree). The layer's plane (mean normal
// through the centroid) gives the LiDAR depth z_l along the pixel's ray.
#pragma once

#include "lidar/lidar_surface.h"
#include "lidar/pinhole_depth_image.h"

#include <cstdint>
#include <vector>

namespace colmap_lidar {

struct LidarDepthRefinementOptions {
  // 0: automatic, 1.5x the median spacing of the LiDAR samples in pixels (at least 3 px): the window
  // then holds the 5-10 nearest samples whatever the LiDAR density and image resolution.
  int window_radius_px = 0;
  // Fold 1: a stereo depth is removed when its point lies farther than max_abs_diff_m +
  // max_rel_diff * z_l from the layer's plane (point-to-plane, as the model is evaluated).
  // The default, 3 mm, is a few sigma of the smoothed LiDAR surface for a VLP-16's 1 cm range noise;
  // a simulated LiDAR rewards tighter thresholds, a real LiDAR's range bias argues against them.
  bool remove_inconsistent = true;
  double max_abs_diff_m = 0.003;
  double max_rel_diff = 0;
  // Where fold 2 could not put the LiDAR depth in its place, a stereo depth is removed only beyond
  // this distance: between the two it is off, but the best there is (removing it costs completeness).
  double max_unreplaceable_diff_m = 0.01;
  // The LiDAR plane is a reference only where the layer is flat: next to a crease the nearest
  // sample's plane may be the other face's, and judging stereo by it removed correct depths. Layers
  // with a sample above this curvature leave the stereo unjudged.
  double max_check_curvature = 0.05;
  // Layer membership: a window sample is on the nearest sample's surface when its point lies within
  // plane_tolerance_m of that plane and its normal within max_normal_angle_deg.
  double plane_tolerance_m = 0.01;
  double max_normal_angle_deg = 30;
  // Fold 2.
  bool fill_holes = true;
  // layer samples in the window
  int min_fill_samples = 4;
  // of the 4 quadrants around the pixel holding a sample (interpolate, never extrapolate past the
  // LiDAR's coverage)
  int min_fill_quadrants = 3;
  // LidarSurface::curvature of every window sample
  double max_fill_curvature = 0.05;
  // between the plane normal and the viewing ray
  double max_fill_view_angle_deg = 75;

  bool Check() const;
};

// kRemoved: no depth, the stereo depth was removed by fold 1 and not filled.
enum class DepthSource : uint8_t { kNone = 0, kStereo = 1, kLidar = 2, kRemoved = 3 };

struct LidarDepthRefinementStats {
  size_t stereo_pixels = 0;         // valid in the input
  size_t stereo_without_lidar = 0;  // kept unchecked: no flat LiDAR surface near
  size_t stereo_confirmed = 0;      // kept: agrees with the LiDAR
  size_t stereo_removed = 0;        // fold 1 (replaced by the LiDAR depth when fold 2 allows)
  size_t filled = 0;                // fold 2 (holes and removed stereo)
  // Pixels without depth next to a LiDAR layer that fold 2 did not fill, by the first failed test.
  size_t fill_refused_edge = 0;    // a second surface in the window, the layer not all round
  size_t fill_refused_sparse = 0;  // too few samples or quadrants
  size_t fill_refused_view_angle = 0;
  size_t fill_refused_curvature = 0;
  int window_radius_px = 0;  // the window used
};

struct RefinedDepth {
  DepthImage depth;
  NormalImage normals;  // LiDAR plane normal where a layer exists, else from the depth map
  std::vector<DepthSource> source;  // row-major
  LidarDepthRefinementStats stats;
};

// `stereo` must have the intrinsics' size (throws std::invalid_argument otherwise).
RefinedDepth RefineDepthWithLidar(const DepthImage& stereo,
                                  const LidarSurface& surface,
                                  const PinholeIntrinsics& intrinsics,
                                  const LidarDepthRefinementOptions& options);

}  // namespace colmap_lidar
