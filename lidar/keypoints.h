// Keypoints for BSC (Dong, Yang et al. 2017): points whose neighbourhood has three well-separated PCA
// eigenvalues (so that a local reference frame is stable), thinned by non-maximum suppression on
// curvature.
#pragma once

#include "lidar/kd_tree.h"
#include "lidar/point_cloud.h"

#include <vector>

namespace colmap_lidar {

struct KeypointOptions {
  // PCA neighbourhood radius [m]
  double radius = 0.5;
  // lambda2 / lambda1 below this (eigenvalues descending)
  double max_ratio_21 = 0.65;
  // lambda3 / lambda2 below this
  double max_ratio_32 = 0.65;
  // more than this many neighbours
  int min_neighbors = 20;
  // greedy non-maximum suppression by curvature within this radius
  double nms_radius = 0.5;
  // strongest after NMS
  size_t max_keypoints = 3000;

  bool Check() const;
};

// Indices into cloud.points (tree built over them), strongest curvature first.
std::vector<size_t> DetectKeypoints(const PointCloud& cloud,
                                    const KdTree3& tree,
                                    const KeypointOptions& options);

}  // namespace colmap_lidar
