// The `stereo_alignment` block of pose_initializer's initialization.json: what the stereo-LiDAR
// alignment did. The alignment is the joint adjustment's start, not a measurement in its cost. Keys
// of its result: "cam_from_lidar": [qw, qx, qy, qz, tx, ty, tz] (quaternion w first,
// metres); "covariance_in_cam": 36 numbers, row-major, rotation [rad] about the camera's axes (left of
// the rotation) then translation [m].
#pragma once

#include "bridge/initialization/stereo_lidar_alignment.h"
#include "bridge/joint/joint_adjuster.h"

#include <nlohmann/json.hpp>

#include <string>

namespace colmap_lidar {

nlohmann::json StereoAlignmentJson(const StereoLidarAlignment& alignment);

}  // namespace colmap_lidar
