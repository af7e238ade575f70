#include "lidar/lidar_pose_graph.h"

#include <Eigen/Eigenvalues>
#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <numeric>
#include <queue>
#include <set>
#include <stdexcept>

namespace colmap_lidar {
namespace {

// Residual of one edge: the left error of the predicted relative pose against the measured one,
// E = T_pred * T_meas^-1 = (R_e, t_e), r = [2 vec(q_e); t_e], which to first order is the ICP's own
// increment [omega, t] in the target frame; whitened by the edge's square-root information.
class RelativePoseError {
 public:
  RelativePoseError(const Eigen::Isometry3d& target_from_source,
                    const Eigen::Matrix<double, 6, 6>& sqrt_information)
      : measured_rotation_(target_from_source.linear()),
        measured_translation_(target_from_source.translation()),
        sqrt_information_(sqrt_information) {}

  static ceres::CostFunction* Create(const Eigen::Isometry3d& target_from_source,
                                     const Eigen::Matrix<double, 6, 6>& sqrt_information) {
    return new ceres::AutoDiffCostFunction<RelativePoseError, 6, 4, 3, 4, 3>(
        new RelativePoseError(target_from_source, sqrt_information));
  }

  template <typename T>
  bool operator()(const T* world_from_target_q,
                  const T* world_from_target_t,
                  const T* world_from_source_q,
                  const T* world_from_source_t,
                  T* residuals) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_i(world_from_target_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_i(world_from_target_t);
    const Eigen::Map<const Eigen::Quaternion<T>> q_j(world_from_source_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_j(world_from_source_t);
    // target_from_source predicted = inverse(world_from_target) * world_from_source
    const Eigen::Quaternion<T> q_pred = q_i.conjugate() * q_j;
    const Eigen::Matrix<T, 3, 1> t_pred = q_i.conjugate() * (t_j - t_i);
    const Eigen::Quaternion<T> q_err = q_pred * measured_rotation_.cast<T>().conjugate();
    Eigen::Matrix<T, 6, 1> r;
    r.template head<3>() = T(2.0) * q_err.vec();
    r.template tail<3>() = t_pred - q_err * measured_translation_.cast<T>();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residuals);
    whitened = sqrt_information_.cast<T>() * r;
    return true;
  }

 private:
  Eigen::Quaterniond measured_rotation_;
  Eigen::Vector3d measured_translation_;
  Eigen::Matrix<double, 6, 6> sqrt_information_;
};

std::vector<double> GlobalHistogram(const StationCloud& station) {
  std::vector<double> histogram;
  for (const BscFeature& feature : station.features) {
    const BscDescriptor& d = feature.variants.front();
    if (histogram.empty()) histogram.assign(d.size() * 64, 0);
    for (size_t bit = 0; bit < histogram.size(); ++bit) {
      histogram[bit] += (d[bit / 64] >> (bit % 64)) & 1;
    }
  }
  const double total = std::max<double>(1, station.features.size());
  for (double& h : histogram) h /= total;
  return histogram;
}

std::vector<std::pair<size_t, size_t>> CandidatePairs(
    const std::vector<const StationCloud*>& stations, size_t max_neighbors, size_t sequential) {
  std::set<std::pair<size_t, size_t>> pairs;
  const size_t n = stations.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j <= std::min(n - 1, i + sequential); ++j) pairs.insert({i, j});
  }
  if (sequential > 0 && max_neighbors == 0) return {pairs.begin(), pairs.end()};
  if (max_neighbors == 0 || max_neighbors + 1 >= n) {
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = i + 1; j < n; ++j) pairs.insert({i, j});
    }
  } else {
    std::vector<std::vector<double>> histograms;
    for (const StationCloud* s : stations) histograms.push_back(GlobalHistogram(*s));
    for (size_t i = 0; i < n; ++i) {
      std::vector<std::pair<double, size_t>> distances;
      for (size_t j = 0; j < n; ++j) {
        if (j == i || histograms[i].size() != histograms[j].size()) continue;
        double l1 = 0;
        for (size_t b = 0; b < histograms[i].size(); ++b)
          l1 += std::abs(histograms[i][b] - histograms[j][b]);
        distances.push_back({l1, j});
      }
      std::sort(distances.begin(), distances.end());
      for (size_t k = 0; k < std::min(max_neighbors, distances.size()); ++k) {
        pairs.insert({std::min(i, distances[k].second), std::max(i, distances[k].second)});
      }
    }
  }
  return {pairs.begin(), pairs.end()};
}

// Symmetric square root of the edge's information: the ICP Hessian scaled so that its best-held
// translation direction has information 1 / sigma^2 (sigma: the pair's ICP RMSE), keeping its shape,
// so a degenerate direction enters the graph with the little information it has.
Eigen::Matrix<double, 6, 6> SqrtInformation(const PairRegistration& r) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> translation(
      r.hessian.bottomRightCorner<3, 3>());
  const double sigma = std::max(r.rmse, 1e-4);
  const double scale = 1 / (std::max(translation.eigenvalues()(2), 1e-12) * sigma * sigma);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(scale * r.hessian);
  const Eigen::Matrix<double, 6, 1> roots = eigen.eigenvalues().cwiseMax(0).cwiseSqrt();
  return eigen.eigenvectors() * roots.asDiagonal() * eigen.eigenvectors().transpose();
}

// Pairs registered and sorted into accepted and refused edges.
void RegisterPairs(const std::vector<const StationCloud*>& stations,
                   const LidarGraphOptions& options,
                   const std::function<void(size_t, size_t)>& progress,
                   LidarGraph* graph) {
  const auto pairs = CandidatePairs(stations, options.max_neighbors, options.sequential);
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto [i, j] = pairs[k];
    LidarEdge edge;
    edge.target = i;
    edge.source = j;
    edge.registration = RegisterStationClouds(*stations[j], *stations[i], options.pair);
    edge.target_from_source = edge.registration.target_from_source;
    (edge.registration.accepted ? graph->edges : graph->refused).push_back(edge);
    if (progress) progress(k + 1, pairs.size());
  }
}

// Edges that break 3-cycles and close none move to the refused list, with the reason.
void RemoveInconsistentEdges(const CycleConsistencyOptions& options, LidarGraph* graph) {
  std::vector<RelativePose> poses;
  for (const LidarEdge& e : graph->edges) {
    poses.push_back({e.target, e.source, e.target_from_source, e.Weight()});
  }
  const CycleCheck check = CheckThreeCycles(poses, options);
  graph->num_cycles = check.num_cycles;
  graph->worst_cycle_translation_m = check.worst_translation_m;
  graph->worst_cycle_rotation_deg = check.worst_rotation_deg;
  std::vector<LidarEdge> kept;
  for (size_t e = 0; e < graph->edges.size(); ++e) {
    if (!check.removed[e]) {
      kept.push_back(graph->edges[e]);
      continue;
    }
    graph->edges[e].registration.accepted = false;
    graph->edges[e].registration.reason = check.reason[e];
    graph->refused.push_back(graph->edges[e]);
  }
  graph->edges = std::move(kept);
}

// Maximum spanning tree (Prim) from the first station of each component: initial poses, components.
void SpanningTreePoses(size_t n, LidarGraph* graph) {
  std::vector<std::vector<const LidarEdge*>> adjacent(n);
  for (const LidarEdge& e : graph->edges) {
    adjacent[e.target].push_back(&e);
    adjacent[e.source].push_back(&e);
  }
  graph->world_from_lidar.assign(n, Eigen::Isometry3d::Identity());
  graph->component.assign(n, -1);
  for (size_t root = 0; root < n; ++root) {
    if (graph->component[root] >= 0) continue;
    const int c = graph->num_components++;
    graph->component[root] = c;
    using Item = std::pair<double, const LidarEdge*>;
    std::priority_queue<Item> queue;
    for (const LidarEdge* e : adjacent[root]) queue.push({e->Weight(), e});
    while (!queue.empty()) {
      const LidarEdge* e = queue.top().second;
      queue.pop();
      const bool target_in = graph->component[e->target] == c;
      const bool source_in = graph->component[e->source] == c;
      if (target_in == source_in) continue;
      const size_t added = target_in ? e->source : e->target;
      // world_from_source = world_from_target * target_from_source
      graph->world_from_lidar[added] =
          target_in ? graph->world_from_lidar[e->target] * e->target_from_source
                    : graph->world_from_lidar[e->source] * e->target_from_source.inverse();
      graph->component[added] = c;
      for (const LidarEdge* next : adjacent[added]) queue.push({next->Weight(), next});
    }
  }
}

// Pose-graph refinement over all accepted edges with a Huber loss on the whitened residuals; the
// first station of each component is the gauge.
void RefinePoses(const LidarGraphOptions& options, LidarGraph* graph) {
  const size_t n = graph->world_from_lidar.size();
  std::vector<Eigen::Quaterniond> rotations(n);
  std::vector<Eigen::Vector3d> translations(n);
  for (size_t i = 0; i < n; ++i) {
    rotations[i] = Eigen::Quaterniond(graph->world_from_lidar[i].linear());
    translations[i] = graph->world_from_lidar[i].translation();
  }
  ceres::Problem problem;
  for (const LidarEdge& e : graph->edges) {
    problem.AddResidualBlock(
        RelativePoseError::Create(e.target_from_source, SqrtInformation(e.registration)),
        new ceres::HuberLoss(options.robust_loss_sigmas),
        rotations[e.target].coeffs().data(),
        translations[e.target].data(),
        rotations[e.source].coeffs().data(),
        translations[e.source].data());
  }
  std::vector<bool> gauge_set(graph->num_components, false);
  for (size_t i = 0; i < n; ++i) {
    if (!problem.HasParameterBlock(rotations[i].coeffs().data())) continue;
    problem.SetManifold(rotations[i].coeffs().data(), new ceres::EigenQuaternionManifold);
    if (!gauge_set[graph->component[i]]) {
      gauge_set[graph->component[i]] = true;
      problem.SetParameterBlockConstant(rotations[i].coeffs().data());
      problem.SetParameterBlockConstant(translations[i].data());
    }
  }
  ceres::Solver::Options solver_options;
  solver_options.max_num_iterations = 100;
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  graph->refinement_initial_cost = summary.initial_cost;
  graph->refinement_final_cost = summary.final_cost;
  for (size_t i = 0; i < n; ++i) {
    graph->world_from_lidar[i] = Eigen::Isometry3d::Identity();
    graph->world_from_lidar[i].linear() = rotations[i].normalized().toRotationMatrix();
    graph->world_from_lidar[i].translation() = translations[i];
  }
}

}  // namespace

double LidarEdge::Weight() const {
  const PairRegistration& r = registration;
  return r.overlap * std::sqrt(std::max(r.constraints.weakest_ratio, 0.0)) / std::max(r.rmse, 1e-4);
}

bool LidarGraphOptions::Check() const {
  if (!(robust_loss_sigmas > 0)) {
    throw std::invalid_argument("LidarGraphOptions: robust_loss_sigmas must be > 0");
  }
  return pair.Check() && cycles.Check();
}

LidarGraph RegisterAllStations(const std::vector<const StationCloud*>& stations,
                               const LidarGraphOptions& options,
                               const std::function<void(size_t, size_t)>& progress) {
  options.Check();
  const size_t n = stations.size();
  if (n == 0) throw std::invalid_argument("RegisterAllStations: no stations");
  LidarGraph graph;
  RegisterPairs(stations, options, progress, &graph);
  if (options.check_cycles) RemoveInconsistentEdges(options.cycles, &graph);
  SpanningTreePoses(n, &graph);
  if (options.refine && !graph.edges.empty()) RefinePoses(options, &graph);
  return graph;
}

}  // namespace colmap_lidar
