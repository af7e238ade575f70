#include "bridge/initialization/edge_consistency.h"

#include <Eigen/Geometry>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace colmap_lidar {
namespace {

double RotationAngleDeg(const Eigen::Quaterniond& rotation) {
  return Eigen::AngleAxisd(rotation).angle() * 180 / M_PI;
}

struct ChainedRotation {
  int component = 0;
  int depth = 0;  // image edges from the component's first station
  Eigen::Quaterniond world_from_cam;
};

// world_from_cam rotations of the stations that image edges connect, one frame per connected
// component of A_c (breadth first from its first station): the camera motion between any two
// stations of a component, without cam_from_lidar.
std::map<colmap::image_t, ChainedRotation> ImageComponentRotations(const ImageEdges& image_edge) {
  std::multimap<colmap::image_t, std::pair<colmap::image_t, Eigen::Quaterniond>> neighbours;
  for (const auto& [pair, cam_i_from_cam_j] : image_edge) {
    neighbours.insert({pair.first, {pair.second, cam_i_from_cam_j.rotation}});
    neighbours.insert({pair.second, {pair.first, cam_i_from_cam_j.rotation.inverse()}});
  }
  std::map<colmap::image_t, ChainedRotation> world_from_cam;
  int component = 0;
  for (const auto& [root, unused] : neighbours) {
    if (world_from_cam.count(root)) continue;
    world_from_cam[root] = {component, 0, Eigen::Quaterniond::Identity()};
    std::vector<colmap::image_t> queue = {root};
    for (size_t q = 0; q < queue.size(); ++q) {
      const auto range = neighbours.equal_range(queue[q]);
      for (auto it = range.first; it != range.second; ++it) {
        const auto& [other, from_other] = it->second;
        if (world_from_cam.count(other)) continue;
        const ChainedRotation& from = world_from_cam.at(queue[q]);
        world_from_cam[other] = {component, from.depth + 1, from.world_from_cam * from_other};
        queue.push_back(other);
      }
    }
    ++component;
  }
  return world_from_cam;
}

}  // namespace

std::vector<LidarStationEdge> DropContradictedLidarEdges(
    const ImageEdges& image_edges,
    const std::vector<LidarStationEdge>& lidar_edges,
    const std::map<colmap::image_t, std::string>& names,
    double max_angle_deg,
    std::vector<std::string>* contradicted) {
  const auto world_from_cam = ImageComponentRotations(image_edges);
  std::vector<LidarStationEdge> kept;
  for (const LidarStationEdge& edge : lidar_edges) {
    const auto cam_i = world_from_cam.find(edge.image_i);
    const auto cam_j = world_from_cam.find(edge.image_j);
    if (cam_i == world_from_cam.end() || cam_j == world_from_cam.end() ||
        cam_i->second.component != cam_j->second.component) {
      kept.push_back(edge);
      continue;
    }
    auto direct = image_edges.find({edge.image_i, edge.image_j});
    if (direct == image_edges.end()) direct = image_edges.find({edge.image_j, edge.image_i});
    const bool chained = direct == image_edges.end();
    const double image_angle =
        chained ? cam_i->second.world_from_cam.angularDistance(cam_j->second.world_from_cam) * 180 /
                      M_PI
                : RotationAngleDeg(direct->second.rotation);
    const double bound =
        max_angle_deg + (chained ? 0.25 * (cam_i->second.depth + cam_j->second.depth) : 0.0);
    const double lidar_angle = RotationAngleDeg(edge.lidar_i_from_lidar_j.rotation);
    if (std::abs(image_angle - lidar_angle) <= bound) {
      kept.push_back(edge);
      continue;
    }
    std::ostringstream reason;
    reason << names.at(edge.image_i) << " " << names.at(edge.image_j) << ": LiDAR " << std::fixed
           << std::setprecision(1) << lidar_angle << " deg, images " << image_angle << " deg";
    contradicted->push_back(reason.str());
    std::cout << "pose_initializer: LiDAR edge " << reason.str()
              << " of rotation: a wrong registration, left out" << std::endl;
  }
  return kept;
}

}  // namespace colmap_lidar
