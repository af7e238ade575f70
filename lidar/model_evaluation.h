// Accuracy of a reconstructed cloud against a ground-truth surface (points with normals), following the
// CloudCompare protocol of Zhen et al. 2019: crop to the structure, optionally align by point-to-plane
// ICP, then per-point distances to the true surface.
#pragma once

#include "lidar/kd_tree.h"
#include "lidar/point_cloud.h"

#include <Eigen/Geometry>

#include <vector>

namespace colmap_lidar {

struct ModelEvaluationOptions {
  // rigid point-to-plane ICP of the model onto the truth first
  bool align_icp = true;
  int icp_max_iterations = 30;
  // model points farther than this from the truth are not the structure
  double crop_distance_m = 0.05;
  // completeness / precision / F-score
  std::vector<double> thresholds_m = {0.002, 0.005, 0.010};

  bool Check() const;
};

struct ModelEvaluation {
  size_t num_model_points = 0;
  size_t num_evaluated = 0;  // after cropping
  size_t num_truth_points = 0;
  Eigen::Isometry3d truth_from_model = Eigen::Isometry3d::Identity();  // the ICP alignment
  bool icp_converged = false;
  int icp_iterations = 0;
  // Unsigned distance of each evaluated model point to the true surface [m].
  std::vector<double> distances;
  // Index into the model cloud of each evaluated point (same order as distances).
  std::vector<size_t> evaluated_indices;
  double mean = 0, median = 0, rmse = 0, p90 = 0, p95 = 0, p99 = 0, max = 0;
  struct AtThreshold {
    double threshold = 0, completeness = 0, precision = 0, f_score = 0;
  };
  std::vector<AtThreshold> at_thresholds;
  // Evaluated points per cm^2 of the true surface they cover (truth samples within the largest
  // threshold of the model, each standing for spacing^2).
  double density_points_per_cm2 = 0;
};

// Distance of `point` to a surface given by samples with normals on a grid of `spacing` (`tree` over
// truth.points): point-to-plane to the best of the 8 nearest samples whose footprint (tangential
// offset <= spacing) contains the point, point-to-point to the nearest sample beyond the border.
double DistanceToSampledSurface(const PointCloud& truth,
                                const KdTree3& tree,
                                double spacing,
                                const Eigen::Vector3d& point);

// `truth` must have normals. Throws std::invalid_argument on empty input or missing normals.
ModelEvaluation EvaluateModel(const PointCloud& model,
                              const PointCloud& truth,
                              const ModelEvaluationOptions& options);

}  // namespace colmap_lidar
