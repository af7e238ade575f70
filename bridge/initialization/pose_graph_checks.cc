#include "bridge/initialization/pose_graph_checks.h"

#include "colmap_ext/rigid3_isometry.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace colmap_lidar {
namespace {

// "name_i name_j (LiDAR): " or "... (images): ".
std::string EdgeLabel(const std::string& name_i, const std::string& name_j, bool from_lidar) {
  return name_i + " " + name_j + (from_lidar ? " (LiDAR): " : " (images): ");
}

}  // namespace

void RemoveInconsistentEdges(const std::map<colmap::image_t, std::string>& names,
                             const CycleConsistencyOptions& options,
                             PoseInitialization* init) {
  std::map<colmap::image_t, size_t> node;
  for (const auto& [image_id, name] : names) node.emplace(image_id, node.size());
  std::vector<RelativePose> poses;
  for (const PoseGraphEdge& e : init->edges) {
    poses.push_back(
        {node.at(e.image_i), node.at(e.image_j), ToIsometry(e.cam_i_from_cam_j), e.weight});
  }
  const CycleCheck check = CheckThreeCycles(poses, options);
  std::vector<PoseGraphEdge> kept;
  for (size_t k = 0; k < init->edges.size(); ++k) {
    const PoseGraphEdge& e = init->edges[k];
    if (!check.removed[k]) {
      kept.push_back(e);
      continue;
    }
    const std::string described =
        EdgeLabel(names.at(e.image_i), names.at(e.image_j), e.from_lidar) + check.reason[k];
    std::cout << "pose_initializer: edge " << described << "; left out" << std::endl;
    init->inconsistent_edges.push_back(described);
    (e.from_lidar ? init->num_lidar_edges : init->num_image_edges)--;
  }
  init->edges = std::move(kept);
}

void ListDisagreeingEdges(const std::vector<RelativePoseEdge>& edges,
                          const PoseGraphSolution& solution,
                          const std::vector<std::string>& node_names,
                          const CycleConsistencyOptions& tolerance,
                          PoseInitialization* init) {
  for (size_t k = 0; k < edges.size(); ++k) {
    const RelativePoseEdge& e = edges[k];
    if (solution.component[e.target] != solution.component[0]) continue;
    const Eigen::Isometry3d error = e.target_from_source.inverse() *
                                    solution.world_from_node[e.target].inverse() *
                                    solution.world_from_node[e.source];
    const double angle_deg = Eigen::AngleAxisd(error.linear()).angle() * 180 / M_PI;
    const double translation_m = error.translation().norm();
    if (angle_deg <= tolerance.max_rotation_deg && translation_m <= tolerance.max_translation_m) {
      continue;
    }
    std::ostringstream described;
    described << EdgeLabel(node_names[e.target], node_names[e.source], init->edges[k].from_lidar)
              << std::fixed << std::setprecision(1) << angle_deg << " deg, " << std::setprecision(3)
              << translation_m << " m from the solved pose graph";
    init->disagreeing_edges.push_back(described.str());
  }
}

void ExplainDegenerateOnly(const std::map<std::string, colmap::image_t>& image_of_station,
                           const std::map<colmap::image_t, std::string>& names,
                           PoseInitialization* init) {
  for (const auto& [station, image_id] : image_of_station) {
    const std::string& name = names.at(image_id);
    if (std::find(init->unreachable.begin(), init->unreachable.end(), name) ==
        init->unreachable.end()) {
      continue;
    }
    for (const LidarPairRecord& pair : init->degenerate_lidar_edges) {
      if (pair.target == station || pair.source == station) {
        init->unreachable_reason[name] =
            "only degenerate LiDAR edges reach it (PoseInitializer.use_degenerate_lidar_edges 1 "
            "uses them)";
      }
    }
  }
}

}  // namespace colmap_lidar
