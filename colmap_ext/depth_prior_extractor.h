// Depth priors for COLMAP keypoints from per-station stereo depth maps (the front end of Zhen et al. 2019): a keypoint
// gets the stereo depth found at it, with sigma_d = d^2 / (b f) * sigma_p (b baseline, f rectified focal
// length, sigma_p the disparity noise in pixels; d^2/(b f) is |dZ/dd| for Z = b f / d).
//
// Depth at a keypoint (x, y) (COLMAP pixel convention: pixel (col, row) spans [col, col+1) x [row, row+1)):
//   1. if the four pixel centres around (x, y) all have depth agreeing within `max_relative_jump`,
//      bilinear interpolation of the four (sub-pixel keypoints on smooth surfaces);
//   2. else the depth of the NEAREST valid pixel centre within `max_radius_px` (Zhen et al. 2019: "valid disparity
//      within 2 px"); nearest rather than a median of the disc, so that a keypoint on a depth edge takes the
//      depth of its own side instead of a blend;
//   3. else no prior (no row in depth_priors).
#pragma once

#include "colmap_ext/extension_database.h"

#include "colmap/feature/types.h"
#include "colmap/mvs/depth_map.h"

#include <optional>
#include <string>
#include <vector>

namespace colmap_lidar {

struct DepthPriorOptions {
  double max_radius_px = 2.0;
  // sigma_p
  double sigma_pixels = 1.0;
  double max_relative_jump = 0.01;

  bool Check() const;
};

// Depth [m] at keypoint location (x, y), or nullopt (see the rules above).
std::optional<double> DepthAtKeypoint(const colmap::mvs::DepthMap& depth_map,
                                      double x,
                                      double y,
                                      const DepthPriorOptions& options);

// sigma_d = d^2 / (b f) * sigma_p.
double DepthSigma(double depth, double baseline_m, double focal_px, double sigma_pixels);

// Priors of one image's keypoints (point2D_idx = keypoint index, as in COLMAP).
std::vector<DepthPrior> ExtractDepthPriors(const colmap::FeatureKeypoints& keypoints,
                                           const colmap::mvs::DepthMap& depth_map,
                                           double baseline_m,
                                           double focal_px,
                                           const DepthPriorOptions& options);

struct ImageDepthPriorCount {
  std::string image_name;
  size_t num_keypoints = 0;
  size_t num_priors = 0;  // 0 also when the image has no depth map
  bool has_depth_map = false;
};

// For every image of the database whose depth map DEPTH_PATH/depth_maps/<stem>.png.geometric.bin exists
// (stem = image file name without extension: left/000.png -> 000), extracts the priors and replaces the
// image's rows in depth_priors, all images in ONE transaction. Prints a line per image.
std::vector<ImageDepthPriorCount> ExtractDatabaseDepthPriors(const std::string& database_path,
                                                             const std::string& depth_path,
                                                             const DepthPriorOptions& options);

}  // namespace colmap_lidar
