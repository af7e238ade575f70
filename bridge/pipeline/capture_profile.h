// What the pipeline decides once about a capture from its data, for the steps after the pose
// initialiser: the camera rig, whether the platform moves (sweeps) and whether its stations rotate
// about one axis only. The pose initialiser records it beside the initial model
// (capture_profile.json) for people and for restarts; the joint step reads it there and decides
// nothing from another report's keys.
//
// capture_profile.json: {"rig": "stereo" | "monocular", "platform": "stations" | "moving",
// "rotation": "two_axes" | "one_axis", "one_axis_in_cam": [x, y, z] (with "one_axis" only: the
// common rotation axis in the camera frame, along which cam_from_lidar's translation is not
// observable from the motion)}.
#pragma once

#include "colmap_ext/station_dataset.h"

#include <Eigen/Core>

#include <optional>
#include <string>

namespace colmap_lidar {

enum class CameraRig { kStereo, kMonocular };
enum class Platform { kStations, kMoving };
// kOneAxis: every relative rotation of the stations is about one axis (a car on a plane); then
// the motion leaves cam_from_lidar's translation along that axis unobserved.
enum class StationRotation { kTwoAxes, kOneAxis };

struct CaptureProfile {
  CameraRig rig = CameraRig::kStereo;
  Platform platform = Platform::kStations;
  StationRotation rotation = StationRotation::kTwoAxes;
  std::optional<Eigen::Vector3d> one_axis_in_cam;

  // A moving platform: rig.json says so (sweeps), or the stations rotate about one axis only.
  bool IsMovingPlatform() const {
    return platform == Platform::kMoving || rotation == StationRotation::kOneAxis;
  }
};

// The profile from the dataset (rig, platform) and the hand-eye's finding on the initial motions:
// `one_axis_in_cam` when every rotation is about that axis, empty otherwise.
CaptureProfile DecideCaptureProfile(const StationDataset& dataset,
                                    const std::optional<Eigen::Vector3d>& one_axis_in_cam);

inline constexpr char kCaptureProfileFile[] = "capture_profile.json";

// Atomic; throws std::runtime_error naming the file when it cannot be written.
void WriteCaptureProfile(const std::string& path, const CaptureProfile& profile);
// Throws std::runtime_error naming the file when it is missing, unreadable or malformed.
CaptureProfile ReadCaptureProfile(const std::string& path);

}  // namespace colmap_lidar
