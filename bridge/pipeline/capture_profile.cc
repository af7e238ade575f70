#include "bridge/pipeline/capture_profile.h"

#include "lidar/util/atomic_file.h"

#include <nlohmann/json.hpp>

#include <array>
#include <fstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

// The value of `key` in `json` that is one of `names`; throws naming the file otherwise.
template <typename Enum, size_t N>
Enum EnumFromJson(const nlohmann::json& json,
                  const char* key,
                  const std::array<std::pair<const char*, Enum>, N>& names,
                  const std::string& path) {
  if (json.contains(key) && json[key].is_string()) {
    for (const auto& [name, value] : names) {
      if (json[key] == name) return value;
    }
  }
  throw std::runtime_error(path + ": \"" + key + "\" is missing or not one of its names");
}

template <typename Enum, size_t N>
const char* NameOf(Enum value, const std::array<std::pair<const char*, Enum>, N>& names) {
  for (const auto& [name, candidate] : names) {
    if (candidate == value) return name;
  }
  return "";
}

const std::array<std::pair<const char*, CameraRig>, 2> kRigNames = {
    {{"stereo", CameraRig::kStereo}, {"monocular", CameraRig::kMonocular}}};
const std::array<std::pair<const char*, Platform>, 2> kPlatformNames = {
    {{"stations", Platform::kStations}, {"moving", Platform::kMoving}}};
const std::array<std::pair<const char*, StationRotation>, 2> kRotationNames = {
    {{"two_axes", StationRotation::kTwoAxes}, {"one_axis", StationRotation::kOneAxis}}};

}  // namespace

CaptureProfile DecideCaptureProfile(const StationDataset& dataset,
                                    const std::optional<Eigen::Vector3d>& one_axis_in_cam) {
  CaptureProfile profile;
  profile.rig = dataset.rig.IsStereo() ? CameraRig::kStereo : CameraRig::kMonocular;
  profile.platform = dataset.rig.IsMovingPlatform() ? Platform::kMoving : Platform::kStations;
  if (one_axis_in_cam) {
    profile.rotation = StationRotation::kOneAxis;
    profile.one_axis_in_cam = one_axis_in_cam->normalized();
  }
  return profile;
}

void WriteCaptureProfile(const std::string& path, const CaptureProfile& profile) {
  nlohmann::json json = {{"rig", NameOf(profile.rig, kRigNames)},
                         {"platform", NameOf(profile.platform, kPlatformNames)},
                         {"rotation", NameOf(profile.rotation, kRotationNames)}};
  if (profile.one_axis_in_cam) {
    const Eigen::Vector3d& axis = *profile.one_axis_in_cam;
    json["one_axis_in_cam"] = {axis.x(), axis.y(), axis.z()};
  }
  WriteFileAtomically(path, json.dump(2) + "\n");
}

CaptureProfile ReadCaptureProfile(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot read " + path);
  const nlohmann::json json = nlohmann::json::parse(file, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded() || !json.is_object()) {
    throw std::runtime_error(path + " is not a capture profile (a JSON object)");
  }
  CaptureProfile profile;
  profile.rig = EnumFromJson(json, "rig", kRigNames, path);
  profile.platform = EnumFromJson(json, "platform", kPlatformNames, path);
  profile.rotation = EnumFromJson(json, "rotation", kRotationNames, path);
  if (profile.rotation == StationRotation::kOneAxis) {
    const nlohmann::json& axis = json.value("one_axis_in_cam", nlohmann::json());
    if (!axis.is_array() || axis.size() != 3 || !axis[0].is_number() || !axis[1].is_number() ||
        !axis[2].is_number()) {
      throw std::runtime_error(path +
                               ": \"one_axis\" rotation without \"one_axis_in_cam\" [x, y, z]");
    }
    profile.one_axis_in_cam = Eigen::Vector3d(axis[0], axis[1], axis[2]);
  }
  return profile;
}

}  // namespace colmap_lidar
