// The simulated sensor pod: a wide-baseline stereo pair (COLMAP camera frames: x right, y down,
// z forward) and a VLP-16 on a motor (LiDAR frame: x forward, y left, z up), and its stations.
// Transforms are target_from_source; quaternions are Eigen (xyzw storage) in memory.
#pragma once

#include "bridge/simulation/scene.h"
#include "colmap_ext/pose_perturbation.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/util/named_choice.h"

#include "colmap/geometry/rigid3.h"

#include <string>
#include <vector>

namespace colmap_lidar {
namespace sim {

enum class Motion {
  kTwoAxes,  // tripod rotations about the vertical, the last stations tilted about a second axis
  kOneAxis,  // every relative rotation about the vertical axis: T_e translation along it unobservable
  kFixedRotation,  // pure translations: T_e translation unobservable
  kDrive,  // a car driving along world x, 0.5-1 m per frame (10 Hz), with a lane change and a swerve
  // a car driving along world x in the right lane, 1-1.5 m per frame, slowing for a U-turn at the
  // far end and returning in the other lane: it passes every place of its way out again (revisits)
  kDriveReturn,
  // a car driving along world x in one lane without turning, 0.5-1 m per frame: the relative
  // rotations are zero, so a hand-eye calibration has nothing to work with
  kStraightDrive,
};
inline constexpr NamedChoices<Motion, 6> kMotionNames = {
    {{"two_axes", Motion::kTwoAxes},
     {"one_axis", Motion::kOneAxis},
     {"fixed_rotation", Motion::kFixedRotation},
     {"drive", Motion::kDrive},
     {"drive_return", Motion::kDriveReturn},
     {"straight_drive", Motion::kStraightDrive}}};
// The motions of a car (frames of one sweep each, in the street).
bool IsDrive(Motion motion);

// Frame period of the driving motion [s]: one LiDAR sweep per frame.
constexpr double kDriveFramePeriod = 0.1;

// A KITTI-like forward camera, 1242x375 * image_scale, 90 deg horizontal FOV, and a second camera
// 0.54 m to its right.
StationRig MakeDriveRig(double image_scale);

// Left and right PINHOLE cameras of width 1028*image_scale with a 48 deg horizontal FOV, 0.38 m baseline.
StationRig MakeStereoRig(double image_scale);

// The pod's true cam_from_lidar: LiDAR 0.25 m above the left camera, near the middle of the baseline,
// mounted with a small, generic misalignment.
colmap::Rigid3d TrueCamFromLidar();

using colmap_lidar::PerturbPose;  // colmap_ext/pose_perturbation.h

// cam_from_world of a camera at `eye` whose optical axis points at `target`, its x axis level
// (perpendicular to world z), then rolled by `roll_deg` about the optical axis.
colmap::Rigid3d CamLookingAt(const Eigen::Vector3d& eye,
                             const Eigen::Vector3d& target,
                             double roll_deg);

// cam_from_world of the left camera of each station, 2-3 m from the structure and looking at it; for
// the drives (IsDrive), of the forward camera at 1.65 m above the street at each frame's
// mid-sweep time.
std::vector<colmap::Rigid3d> MakeStations(const Scene& scene,
                                          int num_stations,
                                          Motion motion,
                                          uint64_t seed);

}  // namespace sim
}  // namespace colmap_lidar
