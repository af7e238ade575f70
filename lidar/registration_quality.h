// How much a registered pair can be trusted, from the data rather than constants tuned to one sensor:
// - the clouds' own plane noise (the point-to-plane residual of each point against its nearest
//   neighbour's plane within the same cloud), against which a pair's ICP RMSE is judged;
// - the constraint analysis of the final point-to-plane ICP Hessian: which directions of the relative
//   pose the pair constrains, and how weakly the weakest is held (a street, a corridor, a flat wall).
#pragma once

#include "lidar/kd_tree.h"
#include "lidar/point_cloud.h"

#include <Eigen/Core>

#include <string>

namespace colmap_lidar {

// RMS of n_q^T (p - q) over an evenly strided subset of at most `max_points` points p, q being p's
// nearest other point in the same cloud (which must have normals; `tree` is built over its points).
// A correct alignment of two clouds of this kind has about this point-to-plane RMSE; 0 if no point has
// a neighbour with a normal.
double PlaneNoiseRms(const PointCloud& cloud, const KdTree3& tree, size_t max_points = 20000);

// Eigen-analysis of a point-to-plane Hessian H in the ICP's [omega, t] parameters (left increment in the
// target frame). Rotations are scaled by `lever_arm_m` (the RMS distance of the source points from the
// target origin), so that every direction is a displacement in metres at the cloud's extent.
struct ConstraintAnalysis {
  // Smallest over largest eigenvalue of the scaled Hessian: 1 = isotropic, near 0 = a direction the
  // pair hardly constrains.
  double weakest_ratio = 0;
  // Unit eigenvector of the weakest direction: [omega * lever_arm, t] in the target frame.
  Eigen::Matrix<double, 6, 1> weakest_direction = Eigen::Matrix<double, 6, 1>::Zero();
  // "tx", "ry", ...: the largest component of the weakest direction, for people.
  std::string WeakestAxisName() const;
};

ConstraintAnalysis AnalyseConstraints(const Eigen::Matrix<double, 6, 6>& hessian,
                                      double lever_arm_m);

}  // namespace colmap_lidar
