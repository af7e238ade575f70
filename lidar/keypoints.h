// Keypoints for BSC (Dong, Yang et al. 2017): points whose neighbourhood has three well-separated PCA
// eigenvalues (so that a local reference frame is stable), thinned by non-maximum suppression on
// curvature.
#pragma once

#include "lidar/kd_tree.h"
#include "lidar/point_cloud.h"

#include <vector>

namespace colmap_lidar {

struct KeypointOptions {
  double radius = 0.5;          // PCA neighbourhood radius [m]
  double max_ratio_21 = 0.65;   // lambda2 / lambda1 below this (eigenvalues descending)
  double max_ratio_32 = 0.65;   // lambda3 / lambda2 below this
  int min_neighbors = 20;       // more than this many neighbours
  double nms_radius = 0.5;      // greedy non-maximum suppression by curvature within this radius
  size_t max_keypoints = 3000;  // strongest after NMS

  bool Check() const;
};

// Indices into cloud.points (tree built over them), strongest curvature first.
std::vector<size_t> DetectKeypoints(const PointCloud& cloud,
                                    const KdTree3& tree,
                                    const KeypointOptions& options);

}  // namespace colmap_lidar
