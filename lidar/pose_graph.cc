#include "lidar/pose_graph.h"

#include "lidar/relative_pose_error.h"
#include "lidar/util/check_option.h"

#include <ceres/ceres.h>

#include <queue>

namespace colmap_lidar {
namespace {

// Maximum spanning tree (Prim) from the first node of each component: initial poses, components.
void SpanningTreePoses(size_t num_nodes,
                       const std::vector<RelativePoseEdge>& edges,
                       PoseGraphSolution* solution) {
  std::vector<std::vector<size_t>> incident(num_nodes);
  for (size_t e = 0; e < edges.size(); ++e) {
    incident[edges[e].target].push_back(e);
    incident[edges[e].source].push_back(e);
  }
  solution->world_from_node.assign(num_nodes, Eigen::Isometry3d::Identity());
  solution->component.assign(num_nodes, -1);
  std::vector<int>& component = solution->component;
  for (size_t root = 0; root < num_nodes; ++root) {
    if (component[root] >= 0) continue;
    const int c = solution->num_components++;
    component[root] = c;
    std::priority_queue<std::pair<double, size_t>> queue;
    for (const size_t e : incident[root]) queue.push({edges[e].weight, e});
    while (!queue.empty()) {
      const RelativePoseEdge& edge = edges[queue.top().second];
      queue.pop();
      const bool target_in = component[edge.target] == c;
      if (target_in == (component[edge.source] == c)) continue;
      const size_t added = target_in ? edge.source : edge.target;
      // world_from_source = world_from_target * target_from_source
      solution->world_from_node[added] =
          target_in ? solution->world_from_node[edge.target] * edge.target_from_source
                    : solution->world_from_node[edge.source] * edge.target_from_source.inverse();
      component[added] = c;
      for (const size_t next : incident[added]) queue.push({edges[next].weight, next});
    }
  }
}

// Refinement over all edges; the first node of each component is the gauge.
void RefinePoses(const std::vector<RelativePoseEdge>& edges,
                 const PoseGraphOptions& options,
                 PoseGraphSolution* solution) {
  const size_t n = solution->world_from_node.size();
  std::vector<Eigen::Quaterniond> rotations(n);
  std::vector<Eigen::Vector3d> translations(n);
  for (size_t i = 0; i < n; ++i) {
    rotations[i] = Eigen::Quaterniond(solution->world_from_node[i].linear());
    translations[i] = solution->world_from_node[i].translation();
  }
  ceres::Problem problem;
  for (const RelativePoseEdge& e : edges) {
    ceres::LossFunction* loss =
        options.loss == RobustLoss::kCauchy
            ? static_cast<ceres::LossFunction*>(new ceres::CauchyLoss(options.loss_scale))
            : new ceres::HuberLoss(options.loss_scale);
    problem.AddResidualBlock(RelativePoseError::Create(e.target_from_source, e.sqrt_information),
                             loss,
                             rotations[e.target].coeffs().data(),
                             translations[e.target].data(),
                             rotations[e.source].coeffs().data(),
                             translations[e.source].data());
  }
  std::vector<bool> gauge_set(solution->num_components, false);
  for (size_t i = 0; i < n; ++i) {
    if (!problem.HasParameterBlock(rotations[i].coeffs().data())) continue;
    problem.SetManifold(rotations[i].coeffs().data(), new ceres::EigenQuaternionManifold);
    if (!gauge_set[solution->component[i]]) {
      gauge_set[solution->component[i]] = true;
      problem.SetParameterBlockConstant(rotations[i].coeffs().data());
      problem.SetParameterBlockConstant(translations[i].data());
    }
  }
  ceres::Solver::Options solver_options;
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  solution->initial_cost = summary.initial_cost;
  solution->final_cost = summary.final_cost;
  for (size_t i = 0; i < n; ++i) {
    solution->world_from_node[i] = Eigen::Isometry3d::Identity();
    solution->world_from_node[i].linear() = rotations[i].normalized().toRotationMatrix();
    solution->world_from_node[i].translation() = translations[i];
  }
}

}  // namespace

Eigen::Matrix<double, 6, 6> DiagonalSqrtInformation(double sigma_rotation_rad,
                                                    double sigma_translation_m) {
  Eigen::Matrix<double, 6, 1> diagonal;
  diagonal << Eigen::Vector3d::Constant(1 / sigma_rotation_rad),
      Eigen::Vector3d::Constant(1 / sigma_translation_m);
  return diagonal.asDiagonal();
}

bool PoseGraphOptions::Check() const {
  LIDAR_CHECK_OPTION(loss != RobustLoss::kNone);
  LIDAR_CHECK_OPTION_GT(loss_scale, 0);
  LIDAR_CHECK_OPTION_GE(max_num_iterations, 0);
  return true;
}

PoseGraphSolution SolvePoseGraph(size_t num_nodes,
                                 const std::vector<RelativePoseEdge>& edges,
                                 const PoseGraphOptions& options) {
  ThrowUnlessValid(options, "PoseGraphOptions");
  for (const RelativePoseEdge& edge : edges) {
    if (edge.target >= num_nodes || edge.source >= num_nodes || edge.target == edge.source) {
      throw std::invalid_argument("SolvePoseGraph: an edge between nodes " +
                                  std::to_string(edge.target) + " and " +
                                  std::to_string(edge.source) + " of " + std::to_string(num_nodes));
    }
  }
  PoseGraphSolution solution;
  SpanningTreePoses(num_nodes, edges, &solution);
  if (options.refine && !edges.empty()) RefinePoses(edges, options, &solution);
  return solution;
}

}  // namespace colmap_lidar
