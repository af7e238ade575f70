// Cloud preprocessing: voxel-grid downsampling, PCA normals with curvature, statistical outlier removal.
#pragma once

#include "lidar/kd_tree.h"
#include "lidar/point_cloud.h"

#include <Eigen/Core>

#include <vector>

namespace colmap_lidar {

// One point per occupied voxel of edge `voxel_size`: the centroid of its points (attributes averaged,
// normals re-normalised). Throws std::invalid_argument for voxel_size <= 0.
PointCloud VoxelDownsample(const PointCloud& cloud, double voxel_size);

struct NormalEstimationOptions {
  // k of the kNN neighbourhood (used when radius == 0)
  int num_neighbors = 20;
  // > 0: radius neighbourhood instead of kNN
  double radius = 0;
  // fewer: the normal is left zero and the curvature set to 1
  int min_neighbors = 5;
  // Normals point towards this position (the sensor origin in the cloud's frame).
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();

  bool Check() const;
};

// Fills cloud->normals by PCA of each point's neighbourhood (smallest eigenvector), oriented towards
// the viewpoint, and `curvature` (if not null) with lambda_min / (lambda_1 + lambda_2 + lambda_3).
// `tree` must be built over cloud->points. Runs in parallel (OpenMP).
void EstimateNormals(const KdTree3& tree,
                     const NormalEstimationOptions& options,
                     PointCloud* cloud,
                     std::vector<double>* curvature = nullptr);

struct OutlierRemovalOptions {
  int num_neighbors = 16;
  // drop points whose mean kNN distance exceeds mean + std_ratio * std
  double std_ratio = 2.0;
};

// Indices of the points kept by statistical outlier removal (ascending).
std::vector<size_t> StatisticalInliers(const PointCloud& cloud,
                                       const KdTree3& tree,
                                       const OutlierRemovalOptions& options);

// The points (and attributes) at `indices`.
PointCloud SelectPoints(const PointCloud& cloud, const std::vector<size_t>& indices);

}  // namespace colmap_lidar
