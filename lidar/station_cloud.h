// A station's cloud prepared for registration: downsampled, with normals, curvature, a k-d tree (built
// once) and BSC features. Not copyable or movable: the tree refers to `cloud.points`; hold it by pointer.
#pragma once

#include "lidar/bsc_descriptor.h"
#include "lidar/kd_tree.h"
#include "lidar/keypoints.h"
#include "lidar/point_cloud.h"
#include "lidar/preprocessing.h"

#include <memory>
#include <vector>

namespace colmap_lidar {

struct StationCloudOptions {
  // downsampling for normals, ICP and association [m]
  double voxel_size = 0.05;
  // coarser copy for keypoints and descriptors [m]
  double feature_voxel_size = 0.1;
  // viewpoint: the LiDAR origin (0, 0, 0)
  NormalEstimationOptions normals;
  KeypointOptions keypoints;
  BscOptions bsc;
  // false: only what association needs (cloud, normals, tree)
  bool compute_features = true;

  bool Check() const;
};

struct StationCloud {
  StationCloud() = default;
  StationCloud(const StationCloud&) = delete;
  StationCloud& operator=(const StationCloud&) = delete;

  PointCloud cloud;                  // point_in_lidar, downsampled, with normals
  std::vector<double> curvature;     // per point of `cloud`
  std::unique_ptr<KdTree3> tree;     // over cloud.points
  std::vector<BscFeature> features;  // positions in the lidar frame
  // Point-to-plane residual RMS of the cloud against itself (PlaneNoiseRms) [m]: what a correct
  // registration's ICP RMSE looks like for this sensor, range noise and spacing.
  double plane_noise_rms = 0;
};

// Downsamples, estimates normals/curvature, detects keypoints and describes them.
std::unique_ptr<StationCloud> PrepareStationCloud(const PointCloud& raw,
                                                  const StationCloudOptions& options);

}  // namespace colmap_lidar
