// Binary Shape Context (BSC) local descriptor, after Dong, Yang et al., "A novel binary shape context
// for 3D local surface description", ISPRS J. Photogramm. 130:431-452, 2017. Our own implementation
// from the paper's description and this project's specification (issue 4); deviations:
//  - the LRF's z axis is signed towards the sensor origin (station clouds know it) rather than by the
//    neighbours' majority; x by the weighted majority of neighbour projections; y = z x x;
//  - where the LRF is ambiguous (lambda_2/lambda_1 above `ambiguity_ratio`, or a weak x majority) the
//    feature keeps the descriptors of the alternative frames (x -> -x, x -> +-y) and matching takes
//    the minimum Hamming distance over variants;
//  - cell features are Gaussian-splatted (sigma = half a cell, 3x3 cells) and normalised by the total
//    weight, so the occupancy threshold (a fraction of the plane's mean cell density) does not depend
//    on the cloud's point density;
//  - comparison bits use one seeded list of N^2 cell pairs for all planes: bit = |D - mean| > std,
//    with mean and std of the pair differences D over that plane (density and mean distance each).
// Layout: for each plane XY, XZ, YZ: N^2 occupancy bits, N^2 density bits, N^2 distance bits, i.e.
// 9 N^2 bits (441 at N = 7), packed into 64-bit words.
#pragma once

#include "lidar/kd_tree.h"
#include "lidar/point_cloud.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace colmap_lidar {

struct BscOptions {
  // R [m]
  double support_radius = 1.5;
  // N
  int grid_size = 7;
  // occupied: cell density > ratio * mean cell density of the plane
  double occupancy_ratio = 0.5;
  // lambda_2 / lambda_1 above this: keep the y-axis variants too
  double ambiguity_ratio = 0.85;
  // |weighted majority| below this fraction: keep the -x variant too
  double sign_ambiguity = 0.1;
  int min_neighbors = 10;
  uint64_t pair_seed = 0x5bd1e995;

  int NumBits() const { return 9 * grid_size * grid_size; }
  int NumWords() const { return (NumBits() + 63) / 64; }
  bool Check() const;
};

using BscDescriptor = std::vector<uint64_t>;

struct BscFeature {
  size_t point_index = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cloud_from_lrf = Eigen::Matrix3d::Identity();  // columns: x, y, z axes
  std::vector<BscDescriptor> variants;                           // the first is the primary frame
};

// Descriptors at the given keypoints of `cloud` (tree built over it); `viewpoint` is the sensor origin.
// Keypoints with too few neighbours are skipped. Parallel over keypoints.
std::vector<BscFeature> ComputeBscFeatures(const PointCloud& cloud,
                                           const KdTree3& tree,
                                           const std::vector<size_t>& keypoints,
                                           const Eigen::Vector3d& viewpoint,
                                           const BscOptions& options);

int HammingDistance(const BscDescriptor& a, const BscDescriptor& b);
// Minimum over the two features' variants.
int BscDistance(const BscFeature& a, const BscFeature& b);

}  // namespace colmap_lidar
