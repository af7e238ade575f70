#include "bridge/initialization/model_completion.h"

#include "colmap_ext/logging.h"
#include "colmap_ext/rigid3_isometry.h"
#include "lidar/pose_graph.h"

#include <algorithm>
#include <filesystem>
#include <set>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

bool IsModelFolder(const fs::path& folder) {
  return fs::is_regular_file(folder / "cameras.bin") || fs::is_regular_file(folder / "cameras.txt");
}

colmap::Reconstruction ReadModel(const fs::path& folder) {
  colmap::Reconstruction model;
  try {
    model.Read(folder.string());
  } catch (const std::exception& error) {
    throw std::runtime_error("cannot read the COLMAP model in " + folder.string() + ": " +
                             error.what());
  }
  if (model.NumRegImages() < 2) {
    throw std::runtime_error("the COLMAP model in " + folder.string() +
                             " has fewer than 2 registered images");
  }
  return model;
}

constexpr double kDegToRad = M_PI / 180.0;

// Nodes of the pose graph: the stations in name order.
struct StationNodes {
  std::map<colmap::image_t, size_t> node_of_image;
  std::vector<colmap::image_t> image_of_node;
};

StationNodes MakeNodes(const std::map<std::string, colmap::image_t>& image_of_station) {
  StationNodes nodes;
  for (const auto& [station, image_id] : image_of_station) {
    nodes.node_of_image[image_id] = nodes.image_of_node.size();
    nodes.image_of_node.push_back(image_id);
  }
  return nodes;
}

// Every pair of images registered in the same model, as cam_i_from_cam_j.
void AddModelEdges(const colmap::Reconstruction& model,
                   const StationNodes& nodes,
                   const Eigen::Matrix<double, 6, 6>& sqrt_information,
                   std::vector<RelativePoseEdge>* edges) {
  std::vector<colmap::image_t> registered;
  for (const colmap::image_t image_id : model.RegImageIds()) {
    if (nodes.node_of_image.count(image_id)) registered.push_back(image_id);
  }
  for (size_t a = 0; a < registered.size(); ++a) {
    for (size_t b = a + 1; b < registered.size(); ++b) {
      const colmap::Rigid3d cam_i_from_cam_j =
          model.Image(registered[a]).CamFromWorld() *
          colmap::Inverse(model.Image(registered[b]).CamFromWorld());
      // Above any LiDAR edge's inlier count: the spanning tree takes the model first.
      edges->push_back({nodes.node_of_image.at(registered[a]),
                        nodes.node_of_image.at(registered[b]),
                        ToIsometry(cam_i_from_cam_j),
                        1e12,
                        sqrt_information});
    }
  }
}

// Why a station outside the first model's component was left out.
std::string UnreachableReason(colmap::image_t image_id,
                              const std::vector<const colmap::Reconstruction*>& models,
                              const std::set<colmap::image_t>& with_lidar_edge) {
  for (size_t k = 1; k < models.size(); ++k) {
    if (models[k]->ExistsImage(image_id) && models[k]->Image(image_id).IsRegistered()) {
      return "registered in model " + std::to_string(k) +
             ", which no LiDAR edge connects to the first model";
    }
  }
  if (!with_lidar_edge.count(image_id)) {
    return "no model registered it and lidar_registrator accepted no edge to it (pairs.txt)";
  }
  return "no model registered it and its LiDAR edges do not reach the first model's stations";
}

}  // namespace

std::vector<colmap::Reconstruction> ReadModels(const std::string& path) {
  const fs::path folder(path);
  if (!fs::is_directory(folder)) throw std::runtime_error("no sparse model folder " + path);
  std::vector<colmap::Reconstruction> models;
  if (IsModelFolder(folder)) {
    models.push_back(ReadModel(folder));
    return models;
  }
  std::vector<fs::path> subfolders;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (entry.is_directory() && IsModelFolder(entry.path())) subfolders.push_back(entry.path());
  }
  std::sort(subfolders.begin(), subfolders.end());
  if (subfolders.empty()) {
    throw std::runtime_error(path +
                             " holds no COLMAP model (cameras.bin or cameras.txt), nor do its "
                             "subfolders");
  }
  for (const fs::path& subfolder : subfolders) models.push_back(ReadModel(subfolder));
  std::stable_sort(models.begin(), models.end(), [](const auto& a, const auto& b) {
    return a.NumRegImages() > b.NumRegImages();
  });
  return models;
}

bool ModelCompletionOptions::Check() const {
  CHECK_OPTION_GT(sigma_rotation_deg, 0);
  CHECK_OPTION_GT(sigma_translation_m, 0);
  CHECK_OPTION_GT(model_sigma_rotation_deg, 0);
  CHECK_OPTION_GT(model_sigma_translation_m, 0);
  return true;
}

CompletedPoses CompleteThroughLidar(const std::vector<const colmap::Reconstruction*>& models,
                                    const std::map<std::string, colmap::image_t>& image_of_station,
                                    const std::map<colmap::image_t, std::string>& image_names,
                                    const std::vector<LidarPairRecord>& lidar_pairs,
                                    const colmap::Rigid3d& cam_from_lidar,
                                    const ModelCompletionOptions& options) {
  THROW_CHECK(options.Check());
  THROW_CHECK(!models.empty());
  const StationNodes nodes = MakeNodes(image_of_station);
  std::vector<RelativePoseEdge> edges;
  for (const colmap::Reconstruction* model : models) {
    AddModelEdges(*model,
                  nodes,
                  DiagonalSqrtInformation(options.model_sigma_rotation_deg * kDegToRad,
                                          options.model_sigma_translation_m),
                  &edges);
  }
  CompletedPoses completed;
  completed.num_model_edges = static_cast<int>(edges.size());
  std::set<colmap::image_t> with_lidar_edge;
  for (const LidarPairRecord& pair : lidar_pairs) {
    const auto target = image_of_station.find(pair.target);
    const auto source = image_of_station.find(pair.source);
    if (target == image_of_station.end() || source == image_of_station.end()) continue;
    with_lidar_edge.insert({target->second, source->second});
    edges.push_back(
        {nodes.node_of_image.at(target->second),
         nodes.node_of_image.at(source->second),
         ToIsometry(cam_from_lidar * pair.target_from_source * colmap::Inverse(cam_from_lidar)),
         static_cast<double>(pair.num_inliers),
         DiagonalSqrtInformation(options.sigma_rotation_deg * kDegToRad,
                                 options.sigma_translation_m)});
    ++completed.num_lidar_edges;
  }
  PoseGraphOptions pose_graph;
  pose_graph.loss = RobustLoss::kCauchy;
  pose_graph.loss_scale = 3.0;
  const PoseGraphSolution solution = SolvePoseGraph(nodes.image_of_node.size(), edges, pose_graph);

  // The first model's first registered station anchors the graph in that model's frame.
  const colmap::Reconstruction& first = *models.front();
  colmap::image_t anchor = colmap::kInvalidImageId;
  for (const colmap::image_t image_id : nodes.image_of_node) {
    if (first.ExistsImage(image_id) && first.Image(image_id).IsRegistered()) {
      anchor = image_id;
      break;
    }
  }
  THROW_CHECK_NE(anchor, colmap::kInvalidImageId) << "the first model registers no station image";
  const size_t anchor_node = nodes.node_of_image.at(anchor);
  const colmap::Rigid3d graph_from_model =
      ToRigid3d(solution.world_from_node[anchor_node]) * first.Image(anchor).CamFromWorld();
  for (size_t k = 0; k < nodes.image_of_node.size(); ++k) {
    const colmap::image_t image_id = nodes.image_of_node[k];
    if (solution.component[k] != solution.component[anchor_node]) {
      completed.unreachable[image_names.at(image_id)] =
          UnreachableReason(image_id, models, with_lidar_edge);
    } else if (first.ExistsImage(image_id) && first.Image(image_id).IsRegistered()) {
      completed.cam_from_world[image_id] = first.Image(image_id).CamFromWorld();
    } else {
      completed.cam_from_world[image_id] =
          ToRigid3d(solution.world_from_node[k].inverse()) * graph_from_model;
    }
  }
  return completed;
}

}  // namespace colmap_lidar
