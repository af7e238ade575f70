// Existing COLMAP models completed through the LiDAR pose graph (the existing-COLMAP workflow).
//
// `colmap mapper` often registers only part of the stations (narrow views of a mostly planar
// structure), or splits them into several models (sparse/0, sparse/1, ...). Once each model is metric
// (bridge/initialization/pose_initializer.h rescales it) and cam_from_lidar is known, one camera
// pose graph (lidar/pose_graph.h) joins
// - model edges: the relative pose of every pair of images registered in the same model, weighted far
//   above any measured edge (a model is kept as it is), and
// - LiDAR edges A_l: lidar_registrator's pairs, cam_i_from_cam_j = T_e lidar_i_from_lidar_j T_e^-1,
// so that the stations no model registered, and the other models, are placed through the LiDAR. The
// world frame is the first model's; its registered images keep their poses exactly.
#pragma once

#include "bridge/initialization/lidar_registration_files.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/reconstruction.h"

#include <map>
#include <string>
#include <vector>

namespace colmap_lidar {

// One model folder (cameras, images, points3D as .bin or .txt), or every model folder directly under
// a parent folder (colmap mapper's sparse/0, sparse/1, ...), the model with the most registered images
// first. Throws std::runtime_error naming the folder when it holds no model or a model cannot be read.
std::vector<colmap::Reconstruction> ReadModels(const std::string& path);

struct ModelCompletionOptions {
  // Whitening of the LiDAR edges (as in the pipeline's pose graph).
  double sigma_rotation_deg = 0.1;
  double sigma_translation_m = 0.005;
  // Whitening of the model edges: the models are kept as they are.
  double model_sigma_rotation_deg = 0.001;
  double model_sigma_translation_m = 0.0001;

  bool Check() const;
};

struct CompletedPoses {
  // Every station reachable from the first model's images, in the first model's (metric) frame.
  std::map<colmap::image_t, colmap::Rigid3d> cam_from_world;
  // Stations left out: image name -> which kind of edge is missing.
  std::map<std::string, std::string> unreachable;
  int num_model_edges = 0;
  int num_lidar_edges = 0;
};

// `models`: metric models of the database whose images are `image_of_station` (station -> image id;
// `image_names` names them); `lidar_pairs`: lidar_registrator's accepted edges.
CompletedPoses CompleteThroughLidar(const std::vector<const colmap::Reconstruction*>& models,
                                    const std::map<std::string, colmap::image_t>& image_of_station,
                                    const std::map<colmap::image_t, std::string>& image_names,
                                    const std::vector<LidarPairRecord>& lidar_pairs,
                                    const colmap::Rigid3d& cam_from_lidar,
                                    const ModelCompletionOptions& options);

}  // namespace colmap_lidar
