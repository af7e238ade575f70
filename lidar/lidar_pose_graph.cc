#include "lidar/lidar_pose_graph.h"

#include "lidar/check_option.h"
#include "lidar/pose_graph.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <numeric>
#include <set>
#include <stdexcept>

namespace colmap_lidar {
namespace {

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

// Spanning tree and refinement over the accepted edges (lidar/pose_graph.h).
void SolveLidarPoseGraph(size_t n, const LidarGraphOptions& options, LidarGraph* graph) {
  std::vector<RelativePoseEdge> edges;
  for (const LidarEdge& e : graph->edges) {
    edges.push_back(
        {e.target, e.source, e.target_from_source, e.Weight(), SqrtInformation(e.registration)});
  }
  PoseGraphOptions pose_graph;
  pose_graph.refine = options.refine;
  pose_graph.loss = "huber";
  pose_graph.loss_scale = options.robust_loss_sigmas;
  PoseGraphSolution solution = SolvePoseGraph(n, edges, pose_graph);
  graph->world_from_lidar = std::move(solution.world_from_node);
  graph->component = std::move(solution.component);
  graph->num_components = solution.num_components;
  graph->refinement_initial_cost = solution.initial_cost;
  graph->refinement_final_cost = solution.final_cost;
}

}  // namespace

double LidarEdge::Weight() const {
  const PairRegistration& r = registration;
  return r.overlap * std::sqrt(std::max(r.constraints.weakest_ratio, 0.0)) / std::max(r.rmse, 1e-4);
}

bool LidarGraphOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(robust_loss_sigmas, 0);
  return pair.Check() && cycles.Check();
}

LidarGraph RegisterAllStations(const std::vector<const StationCloud*>& stations,
                               const LidarGraphOptions& options,
                               const std::function<void(size_t, size_t)>& progress) {
  ThrowUnlessValid(options, "LidarGraphOptions");
  const size_t n = stations.size();
  if (n == 0) throw std::invalid_argument("RegisterAllStations: no stations");
  LidarGraph graph;
  RegisterPairs(stations, options, progress, &graph);
  if (options.check_cycles) RemoveInconsistentEdges(options.cycles, &graph);
  SolveLidarPoseGraph(n, options, &graph);
  return graph;
}

}  // namespace colmap_lidar
