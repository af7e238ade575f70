// A structure known only as a point cloud (a prior scan, a sampled CAD model; world frame, z up) as a
// world for the synthetic joint problem (plan_survey --surface): occlusion and LiDAR scans come from
// spherical z-buffers of its points about the camera or the LiDAR (lidar/spherical_range_image.h),
// with cells three point spacings wide at the nearest surface so that the surface has no holes. The
// scans also see a ground plane at `ground_z` (up to 30 m away), as a real one does: a structure's
// cloud rarely includes the ground, and without it the LiDAR constrains far less.
#pragma once

#include "lidar/point_cloud.h"
#include "bridge/survey/synthetic_joint_problem.h"

#include <memory>

namespace colmap_lidar {
namespace sim {

// The median distance of a point to its nearest neighbour (over up to 2000 points).
double MedianPointSpacing(const PointCloud& cloud);

// Throws std::invalid_argument for a cloud of fewer than 100 finite points.
SyntheticWorld WorldOfSurface(std::shared_ptr<const PointCloud> surface, double ground_z);

}  // namespace sim
}  // namespace colmap_lidar
