// Per-station stereo depth: rectify (StereoRectifier), OpenCV semi-global matching, left-right
// consistency check, speckle filtering, then z-depth in the original left image's pixel grid.
// ComputeDatasetStereoDepth writes the files of stereo_depth_files.h.
#pragma once

#include "colmap_ext/station_dataset.h"
#include "colmap_ext/stereo_rectifier.h"
#include "lidar/util/named_choice.h"

#include <opencv2/core.hpp>

#include <string>

namespace colmap_lidar {

// OpenCV StereoSGBM's modes: 5 paths, 8 paths (full cost volume: much memory), the faster 3-way
// and 4-path HH.
enum class SgbmMode { kSgbm, kHh, kSgbm3Way, kHh4 };
inline constexpr NamedChoices<SgbmMode, 4> kSgbmModeNames = {{{"sgbm", SgbmMode::kSgbm},
                                                              {"hh", SgbmMode::kHh},
                                                              {"3way", SgbmMode::kSgbm3Way},
                                                              {"hh4", SgbmMode::kHh4}}};

struct StereoDepthOptions {
  SgbmMode mode = SgbmMode::kSgbm;
  // The disparity search range follows from a depth range and the rectified rig: for the 0.38 m baseline
  // at 1028 px width this is about 14..300 px (1.5 m .. 30 m).
  double min_depth_m = 1.5;
  double max_depth_m = 30.0;
  // Match each pair top-down and bottom-up (vertically flipped) and average: removes the vertical
  // shift of SGBM's one-directional path aggregation on slanted surfaces at twice the matching time.
  bool vertically_symmetric = true;
  // odd
  int block_size = 5;
  // P1 = p1_factor * block_size^2, P2 = p2_factor * block_size^2 (grey images), OpenCV's recommendation.
  int p1_factor = 8;
  int p2_factor = 32;
  // percent
  int uniqueness_ratio = 10;
  int pre_filter_cap = 63;
  // Speckle filtering (StereoSGBM's own, on both disparity maps): regions smaller than this many
  // pixels whose disparity varies by at most speckle_range px are removed.
  int speckle_window_size = 200;
  double speckle_range_px = 2.0;
  // Left-right check: |d_left(x) - d_right(x - d_left(x))| must not exceed this (pixels).
  double max_left_right_diff_px = 1.0;
  // false: the right disparities come from the left pass's own aggregated costs (SGBM's disp12MaxDiff,
  // as in Hirschmueller's SGM: the check costs nothing; whole pixels; the confidence map is then 255
  // wherever there is depth). true: the mirrored pair is matched again with the right image as the
  // reference (twice the time; sub-pixel check, and the confidence map grades the agreement).
  bool mirrored_left_right_check = false;
  // stations in parallel; -1 = all cores
  int num_threads = -1;

  bool Check() const;
};

struct StereoDepth {
  cv::Mat depth;       // CV_32F, original left grid, metres (z), 0 = invalid
  cv::Mat confidence;  // CV_8U, 0 invalid, 255 = perfect left-right agreement
  double valid_fraction = 0;
};

// One stereo pair (8-bit grey or BGR). Throws std::invalid_argument for sizes that differ from the rig.
StereoDepth ComputeStereoDepth(const cv::Mat& left_image,
                               const cv::Mat& right_image,
                               const StereoRectifier& rectifier,
                               const StereoDepthOptions& options);

// All stations of a dataset, in parallel, with a progress line per station. Errors name the station.
void ComputeDatasetStereoDepth(const StationDataset& dataset,
                               const std::string& output_path,
                               const StereoDepthOptions& options);

}  // namespace colmap_lidar
