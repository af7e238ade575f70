// select_frames: the frames of a drive that go on to the camera steps (SIFT matching, the joint
// problem, the densifier), written as a registration folder of their own
// (bridge/initialization/selected_frames.h).
#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "lidar/util/check_option.h"

namespace colmap_lidar {

void AddFrameSelectionOptions(const std::string& prefix,
                              CommandOptions* manager,
                              FrameSelectionOptions* options) {
  PrefixedOptions add(manager, prefix);
  add.Add("min_distance_m",
          &options->min_distance_m,
          "a frame goes on when the platform moved this far since the last one that did (0: "
          "distance selects none; with min_rotation_deg 0 too: every frame)");
  add.Add("min_rotation_deg", &options->min_rotation_deg, "... or turned this much");
  add.Add("max_frames",
          &options->max_frames,
          "at most this many frames: both spacings grow by one factor until they fit (0: no cap)");
}

int RunSelectFrames(int argc, char** argv) {
  std::string registration_path, output_path;
  FrameSelectionOptions options;
  CommandOptions manager;
  manager.AddRequiredOption(
      "registration_path", &registration_path, "lidar_registrator's output folder");
  manager.AddRequiredOption("output_path",
                            &output_path,
                            "folder for lidar_poses.txt, pairs.txt and selected_frames.txt of "
                            "the selected frames");
  AddFrameSelectionOptions("", &manager, &options);
  manager.Parse(argc, argv);
  ThrowUnlessValid(options, "FrameSelectionOptions");
  RunSelectFramesStep(registration_path, output_path, options);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
