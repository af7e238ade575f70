#include "lidar/trajectory_refinement.h"

#include "lidar/cloud_io.h"
#include "lidar/util/check_option.h"

#include <algorithm>
#include <chrono>
#include <deque>
#include <memory>
#include <set>
#include <stdexcept>
#include <utility>

namespace colmap_lidar {
namespace {

struct WindowFrame {
  size_t index = 0;
  std::unique_ptr<StationCloud> cloud;
};

// The edge of `later` to `earlier` by ICP from the trajectory's relative pose.
LidarEdge RegisterNeighbour(const WindowFrame& earlier,
                            const WindowFrame& later,
                            const std::vector<Eigen::Isometry3d>& world_from_lidar,
                            const PairRegistrationOptions& options) {
  LidarEdge edge;
  edge.target = earlier.index;
  edge.source = later.index;
  const Eigen::Isometry3d guess =
      world_from_lidar[earlier.index].inverse() * world_from_lidar[later.index];
  edge.registration = RegisterFromGuess(*later.cloud, *earlier.cloud, guess, options);
  edge.target_from_source = edge.registration.target_from_source;
  return edge;
}

// graph->edges without the odometry edges that an accepted edge between the same frames replaces.
void DropReplacedOdometryEdges(const std::vector<LidarEdge>& accepted, LidarGraph* graph) {
  std::set<std::pair<size_t, size_t>> measured;
  for (const LidarEdge& e : accepted) measured.insert({e.target, e.source});
  graph->edges.erase(std::remove_if(graph->edges.begin(),
                                    graph->edges.end(),
                                    [&](const LidarEdge& e) {
                                      return e.odometry && measured.count({e.target, e.source});
                                    }),
                     graph->edges.end());
}

}  // namespace

bool TrajectoryRefinementOptions::Check() const {
  LIDAR_CHECK_OPTION_GE(neighbors, 1);
  return cloud.Check() && pair.Check() && drift.Check();
}

TrajectoryRefinement RefineTrajectory(const std::vector<std::string>& cloud_paths,
                                      const TrajectoryRefinementOptions& options,
                                      LidarGraph* graph,
                                      const std::function<void(size_t, size_t)>& progress) {
  if (!options.Check()) throw std::invalid_argument("RefineTrajectory: invalid options");
  if (cloud_paths.size() != graph->world_from_lidar.size()) {
    throw std::invalid_argument("RefineTrajectory: one cloud per pose is needed");
  }
  const auto start = std::chrono::steady_clock::now();
  StationCloudOptions cloud_options = options.cloud;
  cloud_options.compute_features = false;
  TrajectoryRefinement refinement;
  std::vector<LidarEdge> accepted;
  std::deque<WindowFrame> window;
  for (size_t k = 0; k < cloud_paths.size(); ++k) {
    WindowFrame frame{k, PrepareStationCloud(ReadStationCloud(cloud_paths[k]), cloud_options)};
    for (const WindowFrame& earlier : window) {
      LidarEdge edge = RegisterNeighbour(earlier, frame, graph->world_from_lidar, options.pair);
      ++refinement.num_pairs;
      (edge.registration.accepted ? accepted : graph->refused).push_back(std::move(edge));
    }
    window.push_back(std::move(frame));
    if (window.size() > static_cast<size_t>(options.neighbors)) window.pop_front();
    if (progress) progress(k + 1, cloud_paths.size());
  }
  refinement.num_accepted = accepted.size();
  DropReplacedOdometryEdges(accepted, graph);
  graph->edges.insert(graph->edges.end(), accepted.begin(), accepted.end());
  SolveSweepPoseGraph(options.drift, graph);
  refinement.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return refinement;
}

}  // namespace colmap_lidar
