// The densifier as a library call: reads a refined sparse model and its cam_from_lidar, and writes
// the dense model (bridge/dense/densifier.h) into OUTPUT, with a line saying what it did.
#pragma once

#include "bridge/dense/densifier.h"
#include "colmap_ext/station_dataset.h"

#include <string>

namespace colmap_lidar {

struct DensifierPaths {
  std::string input_path;
  std::string cam_from_lidar_path;  // empty: INPUT/cam_from_lidar.txt
  std::string depth_path;
  std::string output_path;
};
void RunDensifierStep(const StationDataset& dataset,
                      const DensifierPaths& paths,
                      const DensifierOptions& options);

}  // namespace colmap_lidar
