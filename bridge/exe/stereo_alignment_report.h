// The `stereo_alignment` block of pose_initializer's initialization.json: written by pose_initializer
// (what the stereo-LiDAR alignment did), read back by joint_adjuster, which takes the alignment as a
// measurement of cam_from_lidar (bridge/extrinsic_deviation_cost.h).
// Keys of the measurement: "cam_from_lidar": [qw, qx, qy, qz, tx, ty, tz] (quaternion w first,
// metres); "covariance_in_cam": 36 numbers, row-major, rotation [rad] about the camera's axes (left of
// the rotation) then translation [m].
#pragma once

#include "bridge/joint_adjuster.h"
#include "bridge/stereo_lidar_alignment.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace colmap_lidar {

nlohmann::json StereoAlignmentJson(const StereoLidarAlignment& alignment);

// The measurement of `initialization` (the parsed initialization.json at `path`), if its alignment
// was used and its covariance is clustered by station (enough stations to measure the spread of
// their errors), with the covariance's diagonal only (see the .cc); nullopt otherwise. Throws naming
// `path` when the block is malformed.
std::optional<ExtrinsicMeasurement> ReadStereoAlignmentMeasurement(
    const nlohmann::json& initialization, const std::string& path);

}  // namespace colmap_lidar
