// The frames of a long drive chosen for the camera steps (lidar/frame_selection.h), written as a
// registration folder of their own that the later steps read like lidar_registrator's output:
//
//   OUTPUT/lidar_poses.txt      world_from_lidar of the kept frames (the registrator's world)
//   OUTPUT/pairs.txt            the registrator's accepted edges between kept frames, and for two
//                               consecutive kept frames joined only through frames left out, the
//                               edge of the trajectory between them (inverse(world_from_a) *
//                               world_from_b) with the weakest quality of the edges it spans
//                               (fewest inliers, least overlap, largest RMSE and noise, weakest
//                               constraint, degenerate if any is)
//   OUTPUT/selected_frames.txt  "<frame> <reason>" per frame: first, distance, rotation, last or
//                               "left out"
//
// Frames are the stations of lidar_poses.txt in name order (time order). The folder is written
// under OUTPUT.partial and renamed when complete. Frames left out keep their poses in the
// registrator's own lidar_poses.txt.
#pragma once

#include "lidar/frame_selection.h"

#include <string>
#include <vector>

namespace colmap_lidar {

struct SelectedFramesSummary {
  size_t num_frames = 0;
  size_t num_kept = 0;
  size_t num_composed_edges = 0;
  double spacing_factor = 1;  // FrameSelection::spacing_factor
};

// Selects from `registration_path`/lidar_poses.txt and writes `output_path` (replacing it). Throws
// std::runtime_error naming a missing or malformed file, std::invalid_argument for bad options.
SelectedFramesSummary WriteSelectedFrames(const std::string& registration_path,
                                          const std::string& output_path,
                                          const FrameSelectionOptions& options);

// The kept frames of `selected_path`/selected_frames.txt, in order. Throws std::runtime_error
// naming the file if it is missing or malformed.
std::vector<std::string> ReadSelectedFrames(const std::string& selected_path);

}  // namespace colmap_lidar
