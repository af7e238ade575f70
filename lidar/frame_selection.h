// Which frames of a long drive go on to the camera steps (SIFT matching, the joint problem, the
// densifier). Walking the trajectory in time order, a frame is kept when the platform has moved at
// least `min_distance_m` or turned at least `min_rotation_deg` since the last kept frame; the first
// and the last frame are always kept. When more than `max_frames` would be kept, both spacings grow
// by one common factor (the smallest that keeps at most `max_frames`), so a drive of thousands of
// sweeps costs the camera steps what a few hundred do. Frames left out keep their odometry poses.
#pragma once

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace colmap_lidar {

struct FrameSelectionOptions {
  // Below this much motion a frame adds no new view: a standstill repeats the same image. A
  // spacing of 0 selects nothing by itself; with both 0 every frame is kept.
  double min_distance_m = 0.3;
  double min_rotation_deg = 5.0;
  // 0: no cap.
  int max_frames = 400;

  bool Check() const;
};

enum class FrameSelectionReason { kFirst, kDistance, kRotation, kLast, kLeftOut };

// "first", "distance", "rotation", "last", "left out".
std::string FrameSelectionReasonName(FrameSelectionReason reason);

struct FrameSelection {
  std::vector<int> kept;                      // frame indices, ascending
  std::vector<FrameSelectionReason> reasons;  // one per frame
  double spacing_factor = 1;                  // the factor applied to both spacings
};

// Selects from `world_from_frame` (in time order). Throws std::invalid_argument for bad options.
FrameSelection SelectFrames(const std::vector<Eigen::Isometry3d>& world_from_frame,
                            const FrameSelectionOptions& options);

}  // namespace colmap_lidar
