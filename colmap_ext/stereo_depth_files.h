// The files of stereo_depth (DIR = --output_path), apart from the matching (stereo_depth.h):
//   DIR/depth_maps/<station>.png.geometric.bin   z-depth [m], COLMAP's DepthMap format, 0 = no depth
//   DIR/confidence_maps/<station>.png            8-bit: 0 invalid, 1..255 = left-right agreement
//   DIR/previews/<station>.png                   colour-mapped inverse depth for people (black = none)
//   DIR/stereo.json                              rectified focal length, baseline, options, per-station
//                                                valid fraction; written last (marks a complete run)
// Every file is written atomically.
#pragma once

#include "colmap_ext/stereo_depth.h"

#include <map>
#include <string>

namespace colmap_lidar {

// Writes one station's depth map, confidence map and preview.
void WriteStationStereoDepth(const std::string& output_path,
                             const std::string& station,
                             const StereoDepth& depth);

std::string StereoDepthMapPath(const std::string& depth_path, const std::string& station);

// What stereo.json records; the depth-prior extractor reads the focal length and baseline back.
struct StereoDepthInfo {
  double rectified_focal_px = 0;
  double baseline_m = 0;
  int min_disparity_px = 0;
  int num_disparities = 0;
  std::map<std::string, double> valid_fraction;  // by station
};
void WriteStereoDepthInfo(const std::string& output_path,
                          const StereoDepthInfo& info,
                          const StereoDepthOptions& options);
// Throws naming the folder when stereo.json is missing or malformed.
StereoDepthInfo ReadStereoDepthInfo(const std::string& depth_path);

}  // namespace colmap_lidar
