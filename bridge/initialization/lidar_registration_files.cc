#include "bridge/initialization/lidar_registration_files.h"

#include "colmap_ext/station_dataset.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

std::string PairLine(const LidarPairRecord& pair) {
  const colmap::Rigid3d& pose = pair.target_from_source;
  std::ostringstream line;
  line << pair.target << " " << pair.source << std::setprecision(12) << " " << pose.rotation.w()
       << " " << pose.rotation.x() << " " << pose.rotation.y() << " " << pose.rotation.z() << " "
       << pose.translation.x() << " " << pose.translation.y() << " " << pose.translation.z() << " "
       << pair.num_inliers << " " << std::setprecision(4) << pair.overlap << " " << pair.rmse_m
       << " " << pair.noise_m << " " << pair.constraint_ratio << " " << pair.weakest_axis << " "
       << (pair.degenerate ? "degenerate" : "determined") << " "
       << (pair.from_identity ? "identity" : "bsc");
  return line.str();
}

// The optional quality columns; false if present but malformed.
bool ReadQualityColumns(std::istringstream* fields, LidarPairRecord* pair) {
  std::string determined, origin;
  if (!(*fields >> pair->overlap)) return fields->eof();
  if (!(*fields >> pair->rmse_m >> pair->noise_m >> pair->constraint_ratio >> pair->weakest_axis >>
        determined >> origin)) {
    return false;
  }
  if (determined != "determined" && determined != "degenerate") return false;
  if (origin != "bsc" && origin != "identity") return false;
  pair->degenerate = determined == "degenerate";
  pair->from_identity = origin == "identity";
  return true;
}

LidarPairRecord ParsePairLine(const std::string& line, const std::string& path, int line_number) {
  std::istringstream fields(line);
  LidarPairRecord pair;
  double qw, qx, qy, qz, tx, ty, tz;
  const bool ok = static_cast<bool>(fields >> pair.target >> pair.source >> qw >> qx >> qy >> qz >>
                                    tx >> ty >> tz >> pair.num_inliers) &&
                  ReadQualityColumns(&fields, &pair);
  const Eigen::Quaterniond rotation(qw, qx, qy, qz);
  if (!ok || !(std::abs(rotation.norm() - 1) < 1e-3) || !Eigen::Vector3d(tx, ty, tz).allFinite()) {
    throw std::runtime_error(path + ":" + std::to_string(line_number) + ": malformed LiDAR pair '" +
                             line + "'");
  }
  pair.target_from_source = colmap::Rigid3d(rotation.normalized(), Eigen::Vector3d(tx, ty, tz));
  return pair;
}

}  // namespace

void WriteLidarPairs(const std::string& path,
                     const std::vector<LidarPairRecord>& accepted,
                     const std::vector<RefusedLidarPair>& refused) {
  std::ostringstream text;
  text << "# colmap-lidar LiDAR pose graph edges (A_l).\n"
          "# target source qw qx qy qz tx ty tz inliers overlap rmse_m noise_m constraint_ratio "
          "weakest_axis determined|degenerate bsc|identity\n"
          "# target_from_source = lidar_target_from_lidar_source, quaternion w first, metres\n";
  for (const LidarPairRecord& pair : accepted) text << PairLine(pair) << "\n";
  for (const RefusedLidarPair& pair : refused) {
    text << "# refused " << pair.target << " " << pair.source << ": " << pair.reason << "\n";
  }
  WriteFileAtomically(path, text.str());
}

std::vector<LidarPairRecord> ReadLidarPairs(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot read LiDAR pose graph " + path);
  std::vector<LidarPairRecord> pairs;
  std::string line;
  for (int line_number = 1; std::getline(file, line); ++line_number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    pairs.push_back(ParsePairLine(line, path, line_number));
  }
  if (file.bad()) throw std::runtime_error("error while reading " + path);
  return pairs;
}

std::vector<std::string> LargestLidarComponent(const std::vector<LidarPairRecord>& pairs) {
  std::map<std::string, std::string> parent;
  const auto find = [&parent](std::string name) {
    while (parent.at(name) != name) name = parent.at(name);
    return name;
  };
  for (const LidarPairRecord& pair : pairs) {
    parent.emplace(pair.target, pair.target);
    parent.emplace(pair.source, pair.source);
  }
  for (const LidarPairRecord& pair : pairs) {
    const std::string a = find(pair.target), b = find(pair.source);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  std::map<std::string, std::vector<std::string>> components;  // by root (its first station)
  for (const auto& [name, unused] : parent) components[find(name)].push_back(name);
  std::vector<std::string> largest;
  for (const auto& [root, members] : components) {
    if (members.size() > largest.size()) largest = members;
  }
  return largest;
}

std::map<std::string, colmap::Rigid3d> LargestComponentLidarPoses(
    const std::string& registration_path) {
  const std::filesystem::path folder(registration_path);
  const std::vector<LidarPairRecord> pairs = ReadLidarPairs((folder / "pairs.txt").string());
  const std::map<std::string, colmap::Rigid3d> world_from_lidar =
      ReadNamedPoses((folder / "lidar_poses.txt").string());
  std::map<std::string, colmap::Rigid3d> poses;
  for (const std::string& station : LargestLidarComponent(pairs)) {
    const auto pose = world_from_lidar.find(station);
    if (pose == world_from_lidar.end()) {
      throw std::runtime_error(registration_path + ": station " + station +
                               " is in pairs.txt but not in lidar_poses.txt");
    }
    poses.emplace(station, pose->second);
  }
  return poses;
}

std::map<std::string, Eigen::Vector3d> StationCameraPositions(
    const std::string& registration_path, const colmap::Rigid3d& cam_from_lidar) {
  const Eigen::Vector3d camera_in_lidar = colmap::Inverse(cam_from_lidar).translation;
  std::map<std::string, Eigen::Vector3d> positions;
  for (const auto& [station, world_from_lidar] : LargestComponentLidarPoses(registration_path)) {
    positions[station] = world_from_lidar * camera_in_lidar;
  }
  return positions;
}

StationDataset WithRegistratorClouds(StationDataset dataset, const std::string& registration_path) {
  if (registration_path.empty()) return dataset;
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    for (const char* folder : {"deskewed", "static"}) {  // the later one wins
      const std::filesystem::path cloud =
          std::filesystem::path(registration_path) / folder / (dataset.stations[i] + ".pcd");
      if (std::filesystem::is_regular_file(cloud)) dataset.cloud_paths[i] = cloud.string();
    }
  }
  return dataset;
}

}  // namespace colmap_lidar
