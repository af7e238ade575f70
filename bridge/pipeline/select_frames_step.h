// select_frames as a library call: the frames of a drive that go on to the camera steps
// (bridge/initialization/selected_frames.h), from lidar_registrator's output folder into OUTPUT, with
// a line saying what was kept.
#pragma once

#include "bridge/initialization/selected_frames.h"

#include <string>

namespace colmap_lidar {

void RunSelectFramesStep(const std::string& registration_path,
                         const std::string& output_path,
                         const FrameSelectionOptions& options);

}  // namespace colmap_lidar
