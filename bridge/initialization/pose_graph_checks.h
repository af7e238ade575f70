// Checks of the camera pose graph A_c v A_l once cam_from_lidar is chosen
// (bridge/initialization/pose_initializer.h): edges that break every cycle they lie on are left
// out, edges the solved graph does not reproduce are reported, and a station left unreachable by leaving out degenerate LiDAR edges says so. Each
// records what it did in the PoseInitialization, for initialization.json.
#pragma once

#include "bridge/initialization/pose_initializer.h"
#include "lidar/cycle_consistency.h"
#include "lidar/pose_graph.h"

#include <map>
#include <string>
#include <vector>

namespace colmap_lidar {

// Edges of A_c v A_l (init->edges, all cam_i_from_cam_j) that break every 2- or 3-cycle they lie on
// beyond `options` (lidar/cycle_consistency.h) are removed from init->edges and described in
// init->inconsistent_edges ("name_i name_j (LiDAR|images): why"), and counted out of
// num_lidar_edges / num_image_edges. `names`: the image name of every station image.
void RemoveInconsistentEdges(const std::map<colmap::image_t, std::string>& names,
                             const CycleConsistencyOptions& options,
                             PoseInitialization* init);

// Edges (init->edges, in the order of `edges`) that the solved graph does not reproduce within
// `tolerance`: a loop longer than a 3-cycle does not close and its stations may be placed wrong.
// Described in init->disagreeing_edges; `node_names`: the image name of each node.
void ListDisagreeingEdges(const std::vector<RelativePoseEdge>& edges,
                          const PoseGraphSolution& solution,
                          const std::vector<std::string>& node_names,
                          const CycleConsistencyOptions& tolerance,
                          PoseInitialization* init);

// The reason of each unreachable station that only left-out degenerate LiDAR edges
// (init->degenerate_lidar_edges) reached.
void ExplainDegenerateOnly(const std::map<std::string, colmap::image_t>& image_of_station,
                           const std::map<colmap::image_t, std::string>& names,
                           PoseInitialization* init);

}  // namespace colmap_lidar
