// Loads what the joint problem needs besides COLMAP's reconstruction: depth priors from our database
// tables, each registered station's LiDAR cloud (downsampled, normals, k-d tree) and the pose graph
// A_c v A_l:
// - A_c: image pairs that COLMAP verified with at least `min_image_pair_inliers` inlier matches;
// - A_l: station pairs whose clouds overlap under the initial poses and T_e (a fraction of sampled source
//   points has a target neighbour within `lidar_overlap_distance_m`), the `max_lidar_neighbors` most
//   overlapping per station, so that LiDAR bridges images that do not overlap.
#pragma once

#include "bridge/joint/joint_adjuster.h"
#include "colmap_ext/station_dataset.h"

#include <map>
#include <memory>
#include <string>

namespace colmap_lidar {

struct JointDataOptions {
  int min_image_pair_inliers = 15;
  double lidar_overlap_distance_m = 0.2;
  double min_lidar_overlap = 0.3;
  // most overlapping partners kept per station
  int max_lidar_neighbors = 4;
  // clouds for the LiDAR term
  double voxel_size_m = 0.05;

  bool Check() const;
};

struct LoadedJointData {
  JointProblemData data;
  std::vector<std::unique_ptr<StationCloud>> clouds;  // owns what data.clouds points to
  // index into the dataset's stations of every registered image (by the image name's stem)
  std::map<colmap::image_t, size_t> station_of_image;
  size_t num_image_pairs = 0;
  size_t num_lidar_pairs = 0;
};

// Station of each registered image: image name "left/<station>.png" (or any name whose stem is a station).
// Throws naming the image if a registered image is not a station of the dataset, or naming the cloud if
// one cannot be read.
std::unique_ptr<LoadedJointData> LoadJointProblemData(const std::string& database_path,
                                                      const StationDataset& dataset,
                                                      const colmap::Reconstruction& reconstruction,
                                                      const colmap::Rigid3d& cam_from_lidar,
                                                      bool load_clouds,
                                                      const JointDataOptions& options);

}  // namespace colmap_lidar
