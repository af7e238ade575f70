// The files of a `lidar_registrator` output folder as the other steps read them.
//
// pairs.txt, read by `pose_initializer` and `import_dataset --matcher spatial`: the accepted LiDAR edges
// (A_l) and, as comments, the refused pairs.
//
//   # comment lines start with '#'
//   target source qw qx qy qz tx ty tz inliers overlap rmse_m noise_m constraint_ratio weakest_axis
//       determined|degenerate bsc|identity
//   # refused target source: reason
//
// target_from_source = lidar_target_from_lidar_source in metres; the quaternion is written w first (as
// in every file colmap-lidar writes; Eigen keeps x, y, z, w in memory). Files of older versions with
// only the first ten columns are read too (the quality columns then keep their defaults).
#pragma once

#include "colmap_ext/station_dataset.h"

#include "colmap/geometry/rigid3.h"

#include <map>
#include <string>
#include <vector>

namespace colmap_lidar {

struct LidarPairRecord {
  std::string target;
  std::string source;
  colmap::Rigid3d target_from_source;
  int num_inliers = 0;
  double overlap = 0;
  double rmse_m = 0;
  double noise_m = 0;
  // Weakest over strongest constrained direction of the pair's ICP (registration_quality.h).
  double constraint_ratio = 1;
  std::string weakest_axis = "-";
  bool degenerate = false;
  // Registered from the identity hypothesis rather than BSC correspondences.
  bool from_identity = false;
};

struct RefusedLidarPair {
  std::string target;
  std::string source;
  std::string reason;
};

// Written atomically (temporary file and rename).
void WriteLidarPairs(const std::string& path,
                     const std::vector<LidarPairRecord>& accepted,
                     const std::vector<RefusedLidarPair>& refused);

// The accepted edges. Throws std::runtime_error naming the file and the line if it cannot be read or a
// line is malformed.
std::vector<LidarPairRecord> ReadLidarPairs(const std::string& path);

// The stations of the largest connected component of the edges (ties: the one with the
// lexicographically first station), sorted by name.
std::vector<std::string> LargestLidarComponent(const std::vector<LidarPairRecord>& pairs);

// world_from_lidar of every station of the largest component, in that component's world (its first
// station's LiDAR frame), from `registration_path`/pairs.txt and lidar_poses.txt. Throws
// std::runtime_error naming a missing file or a station missing from lidar_poses.txt.
std::map<std::string, colmap::Rigid3d> LargestComponentLidarPoses(
    const std::string& registration_path);

// The camera position of every station of the largest component in that component's world (its first
// station's LiDAR frame), from `registration_path`/pairs.txt and lidar_poses.txt (world_from_lidar):
// world_from_lidar * inverse(cam_from_lidar) applied to the origin. Other components have worlds of
// their own, so their stations are left out. Throws std::runtime_error naming a missing file.
std::map<std::string, Eigen::Vector3d> StationCameraPositions(
    const std::string& registration_path, const colmap::Rigid3d& cam_from_lidar);

// `dataset` with each station's cloud replaced by the one lidar_registrator wrote for it:
// `registration_path`/static/<station>.pcd (--remove_moving_points on: moving objects left out), else
// `registration_path`/deskewed/<station>.pcd (--deskew_sweeps 1). An empty path changes nothing.
StationDataset WithRegistratorClouds(StationDataset dataset, const std::string& registration_path);

}  // namespace colmap_lidar
