#include "lidar/lidar_pose_graph.h"

#include "lidar/pose_graph.h"
#include "lidar/util/check_option.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>
#include <sstream>
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

using StationPair = std::pair<size_t, size_t>;

double HistogramDistance(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double l1 = 0;
  for (size_t k = 0; k < a.size(); ++k) l1 += std::abs(a[k] - b[k]);
  return l1;
}

// The `k` stations most similar to station i by global histogram among those `allowed`.
std::vector<size_t> MostSimilar(const std::vector<std::vector<double>>& histograms,
                                size_t i,
                                size_t k,
                                const std::function<bool(size_t)>& allowed) {
  std::vector<std::pair<double, size_t>> distances;
  for (size_t j = 0; j < histograms.size(); ++j) {
    if (j == i || !allowed(j)) continue;
    const double d = HistogramDistance(histograms[i], histograms[j]);
    if (std::isfinite(d)) distances.push_back({d, j});
  }
  const size_t m = std::min(k, distances.size());
  std::partial_sort(distances.begin(), distances.begin() + m, distances.end());
  std::vector<size_t> nearest;
  for (size_t r = 0; r < m; ++r) nearest.push_back(distances[r].second);
  return nearest;
}

StationPair Ordered(size_t i, size_t j) { return {std::min(i, j), std::max(i, j)}; }

std::vector<StationPair> CandidatePairs(const std::vector<std::vector<double>>& histograms,
                                        size_t max_neighbors,
                                        size_t sequential) {
  std::set<StationPair> pairs;
  const size_t n = histograms.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j <= std::min(n - 1, i + sequential); ++j) pairs.insert({i, j});
  }
  if (sequential > 0 && max_neighbors == 0) return {pairs.begin(), pairs.end()};
  const bool all_pairs = max_neighbors == 0 || max_neighbors + 1 >= n;
  for (size_t i = 0; i < n; ++i) {
    if (all_pairs) {
      for (size_t j = i + 1; j < n; ++j) pairs.insert({i, j});
      continue;
    }
    for (size_t j : MostSimilar(histograms, i, max_neighbors, [](size_t) { return true; })) {
      pairs.insert(Ordered(i, j));
    }
  }
  return {pairs.begin(), pairs.end()};
}

// Connected components of the accepted edges (union-find): a label per station; `largest` is the
// label of the largest component.
std::vector<size_t> EdgeComponents(size_t n, const std::vector<LidarEdge>& edges, size_t* largest) {
  std::vector<size_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const std::function<size_t(size_t)> find = [&](size_t x) {
    return parent[x] == x ? x : parent[x] = find(parent[x]);
  };
  for (const LidarEdge& e : edges) parent[find(e.target)] = find(e.source);
  std::vector<size_t> label(n), size(n, 0);
  for (size_t i = 0; i < n; ++i) ++size[label[i] = find(i)];
  *largest = static_cast<size_t>(std::max_element(size.begin(), size.end()) - size.begin());
  return label;
}

// Pairs that may join the components: each station outside the largest component with its `k`
// most similar stations of other components not tried yet (at most k per such station).
std::vector<StationPair> BridgePairs(const std::vector<std::vector<double>>& histograms,
                                     const std::vector<LidarEdge>& edges,
                                     size_t k,
                                     const std::set<StationPair>& tried) {
  size_t largest = 0;
  const std::vector<size_t> label = EdgeComponents(histograms.size(), edges, &largest);
  std::set<StationPair> pairs;
  for (size_t i = 0; i < histograms.size(); ++i) {
    if (label[i] == largest) continue;
    const auto other_untried = [&](size_t j) {
      return label[j] != label[i] && tried.count(Ordered(i, j)) == 0;
    };
    for (size_t j : MostSimilar(histograms, i, k, other_untried)) pairs.insert(Ordered(i, j));
  }
  return {pairs.begin(), pairs.end()};
}

// Pairs registered and sorted into accepted and refused edges; progress counts from `done_before`.
void RegisterPairs(const std::vector<const StationCloud*>& stations,
                   const std::vector<StationPair>& pairs,
                   const LidarGraphOptions& options,
                   const std::function<void(size_t, size_t)>& progress,
                   size_t done_before,
                   LidarGraph* graph) {
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto [i, j] = pairs[k];
    LidarEdge edge;
    edge.target = i;
    edge.source = j;
    edge.registration = RegisterStationClouds(*stations[j], *stations[i], options.pair);
    edge.target_from_source = edge.registration.target_from_source;
    (edge.registration.accepted ? graph->edges : graph->refused).push_back(edge);
    if (progress) progress(done_before + k + 1, done_before + pairs.size());
  }
}

std::vector<RelativePose> RelativePoses(const std::vector<LidarEdge>& edges) {
  std::vector<RelativePose> poses;
  for (const LidarEdge& e : edges) {
    poses.push_back({e.target, e.source, e.target_from_source, e.Weight()});
  }
  return poses;
}

// The edges flagged in `removed` move to the refused list with their `reason`.
void RefuseEdges(const std::vector<bool>& removed,
                 const std::vector<std::string>& reason,
                 LidarGraph* graph) {
  std::vector<LidarEdge> kept;
  for (size_t e = 0; e < graph->edges.size(); ++e) {
    if (!removed[e]) {
      kept.push_back(graph->edges[e]);
      continue;
    }
    graph->edges[e].registration.accepted = false;
    graph->edges[e].registration.reason = reason[e];
    graph->refused.push_back(graph->edges[e]);
  }
  graph->edges = std::move(kept);
}

// Edge e of `graph`, refused by `speed`, registered again from the predicted translation: kept (and
// un-flagged) when ICP from there passes the gates at the neighbours' speed.
void RegisterAtPredictedSpeed(const std::vector<const StationCloud*>& stations,
                              const std::vector<double>& frame_indices,
                              const LidarGraphOptions& options,
                              size_t e,
                              SpeedCheck* speed,
                              LidarGraph* graph) {
  LidarEdge& edge = graph->edges[e];
  Eigen::Isometry3d guess = edge.target_from_source;
  guess.translation() = speed->predicted_translation[e];
  const PairRegistration again =
      RegisterFromGuess(*stations[edge.source], *stations[edge.target], guess, options.pair);
  const double span = std::abs(frame_indices[edge.source] - frame_indices[edge.target]);
  const double predicted = guess.translation().norm() / span;
  const double found = again.target_from_source.translation().norm() / span;
  if (again.accepted && SpeedAgrees(found, predicted, options.speed)) {
    edge.registration = again;
    edge.target_from_source = again.target_from_source;
    speed->removed[e] = false;
    ++graph->num_speed_reregistered;
    return;
  }
  std::ostringstream reason;
  reason << "; ICP from the predicted " << predicted << " m per frame: "
         << (again.accepted ? "slid to " + std::to_string(found) + " m per frame" : again.reason);
  speed->reason[e] += reason.str();
}

// Sweeps: each edge whose speed contradicts its neighbours' (CheckSpeedConsistency) is registered
// again by ICP from the neighbours' velocity (its own rotation kept) and kept if that passes the gates
// at their speed, else refused. Then edges that break 3-cycles and close none are refused.
void RemoveInconsistentEdges(const std::vector<const StationCloud*>& stations,
                             const LidarGraphOptions& options,
                             const std::vector<double>& frame_indices,
                             LidarGraph* graph) {
  if (!frame_indices.empty()) {
    SpeedCheck speed =
        CheckSpeedConsistency(RelativePoses(graph->edges), frame_indices, options.speed);
    for (size_t e = 0; e < graph->edges.size(); ++e) {
      if (speed.removed[e])
        RegisterAtPredictedSpeed(stations, frame_indices, options, e, &speed, graph);
    }
    RefuseEdges(speed.removed, speed.reason, graph);
  }
  if (!options.check_cycles) return;
  const CycleCheck check = CheckThreeCycles(RelativePoses(graph->edges), options.cycles);
  graph->num_cycles = check.num_cycles;
  graph->worst_cycle_translation_m = check.worst_translation_m;
  graph->worst_cycle_rotation_deg = check.worst_rotation_deg;
  RefuseEdges(check.removed, check.reason, graph);
}

// Spanning tree and refinement over the accepted edges (lidar/pose_graph.h).
void SolveLidarPoseGraph(size_t n, const LidarGraphOptions& options, LidarGraph* graph) {
  std::vector<RelativePoseEdge> edges;
  for (const LidarEdge& e : graph->edges) {
    edges.push_back({e.target,
                     e.source,
                     e.target_from_source,
                     e.Weight(),
                     EdgeSqrtInformation(e.registration)});
  }
  PoseGraphOptions pose_graph;
  pose_graph.refine = options.refine;
  pose_graph.loss = RobustLoss::kHuber;
  pose_graph.loss_scale = options.robust_loss_sigmas;
  PoseGraphSolution solution = SolvePoseGraph(n, edges, pose_graph);
  graph->world_from_lidar = std::move(solution.world_from_node);
  graph->component = std::move(solution.component);
  graph->num_components = solution.num_components;
  graph->refinement_initial_cost = solution.initial_cost;
  graph->refinement_final_cost = solution.final_cost;
}

}  // namespace

Eigen::Matrix<double, 6, 6> EdgeSqrtInformation(const PairRegistration& r) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> translation(
      r.hessian.bottomRightCorner<3, 3>());
  const double sigma = std::max(r.rmse, 1e-4);
  const double scale = 1 / (std::max(translation.eigenvalues()(2), 1e-12) * sigma * sigma);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(scale * r.hessian);
  const Eigen::Matrix<double, 6, 1> roots = eigen.eigenvalues().cwiseMax(0).cwiseSqrt();
  return eigen.eigenvectors() * roots.asDiagonal() * eigen.eigenvectors().transpose();
}

double LidarEdge::Weight() const {
  const PairRegistration& r = registration;
  return r.overlap * std::sqrt(std::max(r.constraints.weakest_ratio, 0.0)) / std::max(r.rmse, 1e-4);
}

bool LidarGraphOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(robust_loss_sigmas, 0);
  LIDAR_CHECK_OPTION_GE(max_bridge_rounds, 0);
  return pair.Check() && cycles.Check() && speed.Check();
}

LidarGraph RegisterAllStations(const std::vector<const StationCloud*>& stations,
                               const LidarGraphOptions& options,
                               const std::function<void(size_t, size_t)>& progress,
                               const std::vector<double>& frame_indices) {
  ThrowUnlessValid(options, "LidarGraphOptions");
  const size_t n = stations.size();
  if (n == 0) throw std::invalid_argument("RegisterAllStations: no stations");
  std::vector<std::vector<double>> histograms;
  for (const StationCloud* s : stations) histograms.push_back(GlobalHistogram(*s));
  LidarGraph graph;
  const std::vector<StationPair> pairs =
      CandidatePairs(histograms, options.max_neighbors, options.sequential);
  std::set<StationPair> tried(pairs.begin(), pairs.end());
  RegisterPairs(stations, pairs, options, progress, 0, &graph);
  RemoveInconsistentEdges(stations, options, frame_indices, &graph);
  for (int round = 0; round < options.max_bridge_rounds; ++round) {
    const std::vector<StationPair> bridges =
        BridgePairs(histograms, graph.edges, options.bridge_neighbors, tried);
    if (bridges.empty()) break;
    tried.insert(bridges.begin(), bridges.end());
    graph.num_bridge_pairs += bridges.size();
    RegisterPairs(stations, bridges, options, progress, tried.size() - bridges.size(), &graph);
    RemoveInconsistentEdges(stations, options, frame_indices, &graph);
  }
  SolveLidarPoseGraph(n, options, &graph);
  return graph;
}

}  // namespace colmap_lidar
