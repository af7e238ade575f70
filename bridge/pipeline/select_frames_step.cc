#include "bridge/pipeline/select_frames_step.h"

#include <iomanip>
#include <iostream>

namespace colmap_lidar {

void RunSelectFramesStep(const std::string& registration_path,
                         const std::string& output_path,
                         const FrameSelectionOptions& options) {
  const SelectedFramesSummary summary =
      WriteSelectedFrames(registration_path, output_path, options);
  std::cout << "select_frames: " << summary.num_kept << " of " << summary.num_frames
            << " frames go on to the camera steps (each at least " << std::setprecision(3)
            << summary.spacing_factor * options.min_distance_m << " m or "
            << summary.spacing_factor * options.min_rotation_deg
            << " deg from the kept frame before it";
  if (summary.spacing_factor > 1) {
    std::cout << ": the spacings grown by " << summary.spacing_factor << " to keep at most "
              << options.max_frames;
  }
  std::cout << "); " << summary.num_composed_edges
            << " edges of the trajectory join kept frames across frames left out. Frames left out "
               "keep their poses in "
            << registration_path << "/lidar_poses.txt; the choice is in " << output_path
            << "/selected_frames.txt" << std::endl;
}

}  // namespace colmap_lidar
