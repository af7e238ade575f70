#include "colmap_ext/station_dataset.h"

#include "colmap_ext/text_lines.h"

#include "colmap/sensor/models.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

[[noreturn]] void Fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error(path + ": " + problem);
}

const json& Require(const json& object,
                    const std::string& key,
                    const std::string& path,
                    const std::string& where) {
  if (!object.is_object() || !object.contains(key)) {
    Fail(path, "missing key '" + where + key + "'");
  }
  return object.at(key);
}

std::vector<double> NumberArray(const json& value,
                                size_t expected_size,
                                const std::string& path,
                                const std::string& key) {
  if (!value.is_array() || (expected_size && value.size() != expected_size)) {
    Fail(path, "'" + key + "' must be an array of " + std::to_string(expected_size) + " numbers");
  }
  std::vector<double> numbers;
  for (const json& v : value) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      Fail(path, "'" + key + "' holds a value that is not a finite number");
    }
    numbers.push_back(v.get<double>());
  }
  return numbers;
}

colmap::Camera ParseCamera(const json& value, const std::string& path, const std::string& key) {
  const std::string where = key + ".";
  const json& model = Require(value, "model", path, where);
  if (!model.is_string() || !colmap::ExistsCameraModelWithName(model.get<std::string>())) {
    Fail(path, "'" + where + "model' is not a COLMAP camera model name: " + model.dump());
  }
  colmap::Camera camera;
  camera.model_id = colmap::CameraModelNameToId(model.get<std::string>());
  for (const char* dim : {"width", "height"}) {
    const json& v = Require(value, dim, path, where);
    if (!v.is_number_integer() || v.get<int64_t>() <= 0) {
      Fail(path, "'" + where + dim + "' must be a positive integer");
    }
  }
  camera.width = value["width"].get<size_t>();
  camera.height = value["height"].get<size_t>();
  const size_t num_params = colmap::CameraModelNumParams(camera.model_id);
  const json& params = Require(value, "params", path, where);
  if (!params.is_array() || params.size() != num_params) {
    Fail(path,
         "'" + where + "params' must hold " + std::to_string(num_params) + " values for model " +
             camera.ModelName() + " (" + camera.ParamsInfo() + "), got " +
             std::to_string(params.is_array() ? params.size() : 0));
  }
  camera.params = NumberArray(params, num_params, path, where + "params");
  if (camera.FocalLengthX() <= 0 || camera.FocalLengthY() <= 0) {
    Fail(path, "'" + where + "params' has a non-positive focal length");
  }
  return camera;
}

colmap::Rigid3d ParseRigid(const json& value, const std::string& path, const std::string& key) {
  const std::vector<double> q =
      NumberArray(Require(value, "rotation", path, key + "."), 4, path, key + ".rotation");
  const std::vector<double> t =
      NumberArray(Require(value, "translation", path, key + "."), 3, path, key + ".translation");
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);  // w first
  if (std::abs(rotation.norm() - 1) > 1e-3) {
    Fail(path, "'" + key + ".rotation' is not a unit quaternion [qw,qx,qy,qz]");
  }
  return colmap::Rigid3d(rotation.normalized(), Eigen::Vector3d(t[0], t[1], t[2]));
}

// The guess's optional sigma_rotation_deg and sigma_translation_m (both or neither, positive).
std::optional<StationRig::GuessSigma> ParseGuessSigma(const json& guess, const std::string& path) {
  const bool rotation = guess.contains("sigma_rotation_deg");
  const bool translation = guess.contains("sigma_translation_m");
  if (!rotation && !translation) return std::nullopt;
  if (rotation != translation) {
    Fail(path,
         "'cam_from_lidar_guess' needs both 'sigma_rotation_deg' and 'sigma_translation_m' (or "
         "neither)");
  }
  StationRig::GuessSigma sigma;
  for (const auto& [key, value] :
       {std::pair<const char*, double*>{"sigma_rotation_deg", &sigma.rotation_deg},
        {"sigma_translation_m", &sigma.translation_m}}) {
    const json& number = guess[key];
    if (!number.is_number() || !std::isfinite(number.get<double>()) || number.get<double>() <= 0) {
      Fail(path, std::string("'cam_from_lidar_guess.") + key + "' must be a positive number");
    }
    *value = number.get<double>();
  }
  return sigma;
}

StationRig::LidarSweep ParseSweep(const json& value, const std::string& path) {
  StationRig::LidarSweep sweep;
  if (!value.is_object()) Fail(path, "'lidar.sweep' must be an object");
  if (value.contains("start_azimuth_deg")) {
    const json& azimuth = value["start_azimuth_deg"];
    if (!azimuth.is_number() || !std::isfinite(azimuth.get<double>())) {
      Fail(path, "'lidar.sweep.start_azimuth_deg' must be a finite number");
    }
    sweep.start_azimuth_deg = azimuth.get<double>();
  }
  if (value.contains("counter_clockwise")) {
    if (!value["counter_clockwise"].is_boolean()) {
      Fail(path, "'lidar.sweep.counter_clockwise' must be true or false");
    }
    sweep.counter_clockwise = value["counter_clockwise"].get<bool>();
  }
  return sweep;
}

json CameraToJson(const colmap::Camera& camera) {
  return {{"model", camera.ModelName()},
          {"width", camera.width},
          {"height", camera.height},
          {"params", camera.params}};
}

json RigidToJson(const colmap::Rigid3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation;
  return {{"rotation", {q.w(), q.x(), q.y(), q.z()}},
          {"translation", {pose.translation.x(), pose.translation.y(), pose.translation.z()}}};
}

std::string PoseLine(const colmap::Rigid3d& pose) {
  std::ostringstream line;
  line << std::setprecision(17);
  const Eigen::Quaterniond& q = pose.rotation;
  line << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " " << pose.translation.x()
       << " " << pose.translation.y() << " " << pose.translation.z();
  return line.str();
}

colmap::Rigid3d ParsePose(std::istream& tokens, const std::string& path, size_t line_number) {
  double v[7];
  for (double& x : v) {
    if (!(tokens >> x) || !std::isfinite(x)) {
      Fail(path, "line " + std::to_string(line_number) + ": expected qw qx qy qz tx ty tz");
    }
  }
  const Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
  if (std::abs(q.norm() - 1) > 1e-3) {
    Fail(path,
         "line " + std::to_string(line_number) + ": rotation is not a unit quaternion (qw first)");
  }
  return colmap::Rigid3d(q.normalized(), Eigen::Vector3d(v[4], v[5], v[6]));
}

}  // namespace

StationRig ReadRigJson(const std::string& path) {
  std::ifstream file(path);
  if (!file) Fail(path, "cannot open rig.json");
  json root;
  try {
    root = json::parse(file);
  } catch (const json::exception& error) {
    Fail(path, std::string("not valid JSON: ") + error.what());
  }
  StationRig rig;
  rig.left = ParseCamera(Require(root, "left", path, ""), path, "left");
  const bool has_right = root.contains("right") && !root["right"].is_null();
  if (has_right) {
    rig.right = ParseCamera(root["right"], path, "right");
    rig.right_from_left =
        ParseRigid(Require(root, "right_from_left", path, ""), path, "right_from_left");
    if (rig.BaselineMeters() < 1e-3) {
      Fail(path, "'right_from_left.translation' gives a baseline below 1 mm");
    }
  } else if (root.contains("right_from_left")) {
    Fail(path, "'right_from_left' without a 'right' camera (a monocular rig has neither)");
  }
  if (root.contains("cam_from_lidar_guess") && !root["cam_from_lidar_guess"].is_null()) {
    rig.cam_from_lidar_guess =
        ParseRigid(root["cam_from_lidar_guess"], path, "cam_from_lidar_guess");
    rig.cam_from_lidar_guess_sigma = ParseGuessSigma(root["cam_from_lidar_guess"], path);
  }
  if (root.contains("lidar")) {
    const json& lidar = root["lidar"];
    if (lidar.contains("model")) rig.lidar_model = lidar["model"].get<std::string>();
    if (lidar.contains("range_noise_m")) {
      rig.lidar_range_noise_m = lidar["range_noise_m"].get<double>();
    }
    if (lidar.contains("sweep")) rig.lidar_sweep = ParseSweep(lidar["sweep"], path);
    if (lidar.contains("moving_platform")) {
      if (!lidar["moving_platform"].is_boolean()) {
        Fail(path, "'lidar.moving_platform' must be true or false");
      }
      rig.moving_platform = lidar["moving_platform"].get<bool>();
    }
  }
  return rig;
}

void WriteRigJson(const std::string& path, const StationRig& rig) {
  json root;
  root["comment"] =
      "colmap-lidar station rig. Cameras are COLMAP camera models (params in "
      "COLMAP's order). Transforms are target_from_source "
      "(x_target = R x_source + t), rotation as a unit quaternion "
      "[qw, qx, qy, qz] (w first), translation in metres.";
  root["left"] = CameraToJson(rig.left);
  if (rig.IsStereo()) {
    root["right"] = CameraToJson(*rig.right);
    root["right_from_left"] = RigidToJson(rig.right_from_left);
  }
  if (rig.cam_from_lidar_guess) {
    root["cam_from_lidar_guess"] = RigidToJson(*rig.cam_from_lidar_guess);
    if (rig.cam_from_lidar_guess_sigma) {
      root["cam_from_lidar_guess"]["sigma_rotation_deg"] =
          rig.cam_from_lidar_guess_sigma->rotation_deg;
      root["cam_from_lidar_guess"]["sigma_translation_m"] =
          rig.cam_from_lidar_guess_sigma->translation_m;
    }
  }
  if (!rig.lidar_model.empty()) {
    root["lidar"] = {{"model", rig.lidar_model}, {"range_noise_m", rig.lidar_range_noise_m}};
  }
  if (rig.moving_platform) root["lidar"]["moving_platform"] = true;
  if (rig.lidar_sweep) {
    root["lidar"]["sweep"] = {{"start_azimuth_deg", rig.lidar_sweep->start_azimuth_deg},
                              {"counter_clockwise", rig.lidar_sweep->counter_clockwise}};
  }
  WriteFileAtomically(path, root.dump(2) + "\n");
}

std::string StationDataset::LeftImagePath(size_t i) const {
  return (fs::path(root) / "images" / LeftImageName(i)).string();
}

std::string StationDataset::RightImagePath(size_t i) const {
  return (fs::path(root) / "images" / "right" / (stations.at(i) + ".png")).string();
}

std::string StationDataset::LeftImageName(size_t i) const {
  return "left/" + stations.at(i) + ".png";
}

std::string StationDataset::GroundTruthPath(const std::string& name) const {
  return (fs::path(root) / "ground_truth" / name).string();
}

bool StationDataset::HasGroundTruth() const {
  return fs::is_regular_file(GroundTruthPath("cam_from_world.txt"));
}

bool StationDataset::HasReferenceExtrinsic() const {
  return fs::is_regular_file(GroundTruthPath("cam_from_lidar.txt"));
}

namespace {

// Every cloud of ROOT/lidar is a station with a left image, and no station has two clouds.
void CheckEveryCloudHasOneImage(const std::string& root, const std::vector<std::string>& stations) {
  const fs::path lidar_dir = fs::path(root) / "lidar";
  std::map<std::string, std::string> cloud_of_station;
  for (const auto& entry : fs::directory_iterator(lidar_dir)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".pcd" && ext != ".ply" && ext != ".bin") continue;
    const std::string station = entry.path().stem().string();
    const auto [it, inserted] = cloud_of_station.emplace(station, entry.path().string());
    if (!inserted) {
      Fail(entry.path().string(),
           "station " + station + " has a second cloud (" + it->second + "); keep one");
    }
    if (!std::binary_search(stations.begin(), stations.end(), station)) {
      Fail(entry.path().string(),
           "a cloud without a left image (" +
               (fs::path(root) / "images" / "left" / (station + ".png")).string() + ")");
    }
  }
}

// "<station> v1 .. vN" per line of an optional dataset file, one line per station, as a table in
// station order; an absent file gives an empty table.
std::vector<std::vector<double>> ReadStationTable(const StationDataset& dataset,
                                                  const std::string& name,
                                                  size_t num_values) {
  const std::string path = (fs::path(dataset.root) / name).string();
  if (!fs::is_regular_file(path)) return {};
  std::map<std::string, std::vector<double>> rows;
  ForEachDataLine(path, [&](const std::string& line, size_t number) {
    std::istringstream tokens(line);
    std::string station, rest;
    tokens >> station;
    std::getline(tokens, rest);
    if (!rows.emplace(station, ParseNumberLine(rest, path, number, num_values)).second) {
      FailAtLine(path, number, "station '" + station + "' appears twice");
    }
  });
  std::vector<std::vector<double>> table;
  for (const std::string& station : dataset.stations) {
    const auto it = rows.find(station);
    if (it == rows.end()) Fail(path, "no line for station " + station);
    table.push_back(it->second);
  }
  return table;
}

// timestamps.txt and sweep_times.txt. Sweeps end after they start and start later in station order
// (the de-skewing takes a station's neighbours in name order as its neighbours in time).
void ReadOptionalTimes(StationDataset* dataset) {
  for (const std::vector<double>& row : ReadStationTable(*dataset, "timestamps.txt", 1)) {
    dataset->frame_times.push_back(row[0]);
  }
  for (const std::vector<double>& row : ReadStationTable(*dataset, "sweep_times.txt", 2)) {
    if (!(row[1] > row[0]) ||
        (!dataset->sweep_times.empty() && !(row[0] > dataset->sweep_times.back().first))) {
      Fail(dataset->root + "/sweep_times.txt",
           "sweeps must end after they start and start later in station (name) order");
    }
    dataset->sweep_times.emplace_back(row[0], row[1]);
  }
}

}  // namespace

StationDataset RestrictToStations(StationDataset dataset, const std::vector<std::string>& kept) {
  std::set<std::string> wanted(kept.begin(), kept.end());
  StationDataset restricted = dataset;
  restricted.stations.clear();
  restricted.cloud_paths.clear();
  restricted.frame_times.clear();
  restricted.sweep_times.clear();
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    if (wanted.erase(dataset.stations[i]) == 0) continue;
    restricted.stations.push_back(dataset.stations[i]);
    restricted.cloud_paths.push_back(dataset.cloud_paths[i]);
    if (!dataset.frame_times.empty()) restricted.frame_times.push_back(dataset.frame_times[i]);
    if (!dataset.sweep_times.empty()) restricted.sweep_times.push_back(dataset.sweep_times[i]);
  }
  if (!wanted.empty()) throw std::runtime_error(dataset.root + ": no station " + *wanted.begin());
  return restricted;
}

StationDataset ReadStationDataset(const std::string& root) {
  if (!fs::is_directory(root)) Fail(root, "dataset directory does not exist");
  StationDataset dataset;
  dataset.root = root;
  dataset.rig = ReadRigJson((fs::path(root) / "rig.json").string());
  const fs::path left_dir = fs::path(root) / "images" / "left";
  if (!fs::is_directory(left_dir)) {
    Fail(left_dir.string(), "directory of left images does not exist");
  }
  for (const auto& entry : fs::directory_iterator(left_dir)) {
    if (entry.path().extension() == ".png") {
      dataset.stations.push_back(entry.path().stem().string());
    }
  }
  std::sort(dataset.stations.begin(), dataset.stations.end());
  if (dataset.stations.empty()) Fail(left_dir.string(), "no .png images");
  const fs::path right_dir = fs::path(root) / "images" / "right";
  if (!dataset.rig.IsStereo() && fs::is_directory(right_dir)) {
    Fail((fs::path(root) / "rig.json").string(),
         "no 'right' camera, but " + right_dir.string() +
             " exists: add the right camera and right_from_left for a stereo rig, or remove the "
             "folder for a monocular one");
  }
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    if (dataset.rig.IsStereo() && !fs::is_regular_file(dataset.RightImagePath(i))) {
      Fail(dataset.RightImagePath(i), "missing right image of station " + dataset.stations[i]);
    }
    std::string cloud;
    for (const char* ext : {".pcd", ".ply", ".bin"}) {
      const fs::path candidate = fs::path(root) / "lidar" / (dataset.stations[i] + ext);
      if (fs::is_regular_file(candidate)) {
        cloud = candidate.string();
        break;
      }
    }
    if (cloud.empty()) {
      Fail((fs::path(root) / "lidar" / (dataset.stations[i] + ".pcd")).string(),
           "missing LiDAR cloud of station " + dataset.stations[i]);
    }
    dataset.cloud_paths.push_back(cloud);
  }
  CheckEveryCloudHasOneImage(root, dataset.stations);
  ReadOptionalTimes(&dataset);
  return dataset;
}

void WriteStationTimes(const std::string& path,
                       const std::vector<std::string>& stations,
                       const std::vector<double>& times) {
  std::ostringstream out;
  out << "# <station> time [s]: when the station's frame was taken (the camera's trigger)\n"
      << std::fixed << std::setprecision(9);
  for (size_t k = 0; k < stations.size(); ++k) out << stations[k] << " " << times.at(k) << "\n";
  WriteFileAtomically(path, out.str());
}

void WriteSweepTimes(const std::string& path,
                     const std::vector<std::string>& stations,
                     const std::vector<std::pair<double, double>>& times) {
  std::ostringstream out;
  out << "# <station> start end [s]: the first and last point of the station's LiDAR sweep\n"
      << std::fixed << std::setprecision(9);
  for (size_t k = 0; k < stations.size(); ++k) {
    out << stations[k] << " " << times.at(k).first << " " << times.at(k).second << "\n";
  }
  WriteFileAtomically(path, out.str());
}

std::map<std::string, colmap::Rigid3d> ReadNamedPoses(const std::string& path) {
  std::ifstream file(path);
  if (!file) Fail(path, "cannot open pose file");
  std::map<std::string, colmap::Rigid3d> poses;
  std::string line;
  size_t line_number = 0;
  while (std::getline(file, line)) {
    ++line_number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream tokens(line);
    std::string name;
    tokens >> name;
    if (poses.count(name)) {
      Fail(path, "line " + std::to_string(line_number) + ": station '" + name + "' appears twice");
    }
    poses[name] = ParsePose(tokens, path, line_number);
  }
  return poses;
}

void WriteNamedPoses(const std::string& path,
                     const std::string& header_comment,
                     const std::map<std::string, colmap::Rigid3d>& poses) {
  std::ostringstream out;
  out << "# " << header_comment << "\n"
      << "# <station> qw qx qy qz tx ty tz   (target_from_source, quaternion w "
         "first, metres)\n";
  for (const auto& [name, pose] : poses) out << name << " " << PoseLine(pose) << "\n";
  WriteFileAtomically(path, out.str());
}

colmap::Rigid3d ReadPoseFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) Fail(path, "cannot open pose file");
  std::string line;
  size_t line_number = 0;
  while (std::getline(file, line)) {
    ++line_number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream tokens(line);
    return ParsePose(tokens, path, line_number);
  }
  Fail(path, "no pose line (expected qw qx qy qz tx ty tz)");
}

void WritePoseFile(const std::string& path,
                   const std::string& header_comment,
                   const colmap::Rigid3d& target_from_source) {
  WriteFileAtomically(path,
                      "# " + header_comment +
                          "\n# qw qx qy qz tx ty tz   (quaternion w "
                          "first, metres)\n" +
                          PoseLine(target_from_source) + "\n");
}

}  // namespace colmap_lidar
