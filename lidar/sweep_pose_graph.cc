#include "lidar/sweep_pose_graph.h"

#include "lidar/pose_graph.h"
#include "lidar/util/check_option.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace colmap_lidar {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// The inverse square root of a covariance.
Matrix6d SqrtInformationOf(const Matrix6d& covariance) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(covariance);
  return eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().cwiseSqrt().asDiagonal() *
         eigen.eigenvectors().transpose();
}

// An odometry edge's square-root information: its step's drift plus its registration's covariance.
Matrix6d OdometrySqrtInformation(const LidarEdge& edge, const OdometryDrift& drift) {
  const double step_m = edge.target_from_source.translation().norm();
  return SqrtInformationOf(step_m * step_m * drift.PerMetre() +
                           RegistrationCovariance(edge.registration));
}

}  // namespace

Eigen::Matrix<double, 6, 6> OdometryDrift::PerMetre() const {
  const double rotation = rotation_deg_per_m * M_PI / 180.0;
  Eigen::Matrix<double, 6, 1> variance;
  variance << Eigen::Vector3d::Constant(rotation * rotation),
      Eigen::Vector3d::Constant(translation * translation);
  return variance.asDiagonal();
}

bool OdometryDrift::Check() const {
  LIDAR_CHECK_OPTION_GT(translation, 0);
  LIDAR_CHECK_OPTION_GT(rotation_deg_per_m, 0);
  return true;
}

Eigen::Matrix<double, 6, 6> RegistrationCovariance(const PairRegistration& registration) {
  const Matrix6d root = EdgeSqrtInformation(registration);
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(root.transpose() * root);
  const double floor = std::max(eigen.eigenvalues().maxCoeff(), 1e-30) * 1e-12;
  const Eigen::Matrix<double, 6, 1> variances = eigen.eigenvalues().cwiseMax(floor).cwiseInverse();
  return eigen.eigenvectors() * variances.asDiagonal() * eigen.eigenvectors().transpose();
}

void SolveSweepPoseGraph(const OdometryDrift& drift, LidarGraph* graph) {
  std::vector<RelativePoseEdge> edges;
  for (const LidarEdge& e : graph->edges) {
    edges.push_back(
        {e.target,
         e.source,
         e.target_from_source,
         e.odometry ? 1.0 : 0.0,
         e.odometry ? OdometrySqrtInformation(e, drift) : EdgeSqrtInformation(e.registration)});
  }
  PoseGraphSolution solution =
      SolvePoseGraph(graph->world_from_lidar.size(), edges, PoseGraphOptions());
  graph->world_from_lidar = std::move(solution.world_from_node);
  graph->component = std::move(solution.component);
  graph->num_components = solution.num_components;
  graph->refinement_initial_cost = solution.initial_cost;
  graph->refinement_final_cost = solution.final_cost;
}

}  // namespace colmap_lidar
