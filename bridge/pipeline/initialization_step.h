// The pose initialiser as a pipeline step, a library call: initial station poses, cam_from_lidar
// and landmarks from the images' pose graph and the LiDAR registration (bridge/initialization/
// pose_initializer.h), or an existing COLMAP model rescaled to metres and completed through the
// LiDAR. Writes OUTPUT/ atomically: the initial sparse model, cam_from_lidar.txt,
// initialization.json (what the initialiser did, for people) and capture_profile.json (what the
// later steps follow, bridge/pipeline/capture_profile.h).
#pragma once

#include "bridge/initialization/pose_initializer.h"
#include "bridge/pipeline/capture_profile.h"
#include "colmap_ext/station_dataset.h"

#include <string>

namespace colmap_lidar {

struct PoseInitializerPaths {
  std::string database_path;
  std::string registration_path;  // may be empty: no LiDAR edges
  std::string input_path;         // an existing model to rescale; empty: initialise
  std::string output_path;
  std::string depth_path;  // stereo_depth's output; empty: no stereo-LiDAR alignment
};
// Returns the capture profile it decided (also recorded as OUTPUT/capture_profile.json).
CaptureProfile RunPoseInitializerStep(const StationDataset& dataset,
                                      const PoseInitializerPaths& paths,
                                      const PoseInitializerOptions& options);

}  // namespace colmap_lidar
