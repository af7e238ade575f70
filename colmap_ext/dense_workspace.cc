#include "colmap_ext/dense_workspace.h"

#include "colmap/mvs/depth_map.h"
#include "colmap/mvs/normal_map.h"
#include "colmap/sensor/models.h"

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

void EnsureParent(const std::string& path) { fs::create_directories(fs::path(path).parent_path()); }

// COLMAP's depth and normal map files are "width&height&depth&" and width x height x depth float32.
// COLMAP's reader trusts the header (a claimed 10^6 x 10^6 map is allocated); ours is checked first
// against the file's size.
void CheckColmapMatrixFile(const std::string& path, size_t channels) {
  std::ifstream file(path, std::ios::binary);
  size_t dims[3] = {0, 0, 0};
  for (size_t& dim : dims) {
    std::string digits;
    char c = 0;
    while (file.get(c) && c != '&' && digits.size() < 10) digits.push_back(c);
    if (c != '&' || digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) {
      throw std::runtime_error(
          "Not a COLMAP depth or normal map (no width&height&depth& header): " + path);
    }
    dim = std::stoul(digits);
  }
  const uint64_t expected = uint64_t(dims[0]) * dims[1] * dims[2] * sizeof(float);
  const uint64_t present = fs::file_size(path) - static_cast<uint64_t>(file.tellg());
  if (dims[2] != channels || dims[0] == 0 || dims[1] == 0 || expected != present) {
    throw std::runtime_error("Not a COLMAP map of " + std::to_string(channels) +
                             " channel(s): " + path + " claims " + std::to_string(dims[0]) + "x" +
                             std::to_string(dims[1]) + "x" + std::to_string(dims[2]) +
                             " floats in " + std::to_string(present) + " bytes");
  }
}

}  // namespace

bool IsPinholeCamera(const colmap::Camera& camera) {
  return camera.model_id == colmap::SimplePinholeCameraModel::model_id ||
         camera.model_id == colmap::PinholeCameraModel::model_id;
}

cv::Mat ReadColmapDepthMap(const std::string& path) {
  if (!fs::is_regular_file(path)) {
    throw std::runtime_error("No depth map at " + path);
  }
  CheckColmapMatrixFile(path, 1);
  colmap::mvs::DepthMap map;
  try {
    map.Read(path);
  } catch (const std::exception& error) {
    throw std::runtime_error("Cannot read the depth map " + path + ": " + error.what());
  }
  if (map.GetWidth() == 0 || map.GetHeight() == 0 || map.GetDepth() != 1) {
    throw std::runtime_error("Not a depth map (empty or several channels): " + path);
  }
  cv::Mat depth(static_cast<int>(map.GetHeight()), static_cast<int>(map.GetWidth()), CV_32F);
  std::copy(map.GetData().begin(), map.GetData().end(), depth.ptr<float>());
  return depth;
}

DenseWorkspace::DenseWorkspace(std::string root) : root_(std::move(root)) {
  for (const char* folder : {"images", "sparse", "stereo/depth_maps", "stereo/normal_maps"}) {
    fs::create_directories(fs::path(root_) / folder);
  }
}

std::string DenseWorkspace::ImagePath(const std::string& image_name) const {
  return (fs::path(root_) / "images" / image_name).string();
}

std::string DenseWorkspace::DepthMapPath(const std::string& image_name) const {
  return (fs::path(root_) / "stereo" / "depth_maps" / (image_name + ".geometric.bin")).string();
}

std::string DenseWorkspace::NormalMapPath(const std::string& image_name) const {
  return (fs::path(root_) / "stereo" / "normal_maps" / (image_name + ".geometric.bin")).string();
}

void DenseWorkspace::WriteSparse(const colmap::Reconstruction& reconstruction) const {
  colmap::Reconstruction workspace_model = reconstruction;
  for (const auto& [camera_id, original] : reconstruction.Cameras()) {
    if (!IsPinholeCamera(original)) {
      throw std::invalid_argument("The dense workspace needs undistorted images: camera " +
                                  std::to_string(camera_id) + " is " + original.ModelName() +
                                  " (only SIMPLE_PINHOLE and PINHOLE are supported)");
    }
    colmap::Camera& camera = workspace_model.Camera(camera_id);
    camera.model_id = colmap::PinholeCameraModel::model_id;
    camera.params = {original.FocalLengthX(),
                     original.FocalLengthY(),
                     original.PrincipalPointX() - 0.5,
                     original.PrincipalPointY() - 0.5};
  }
  workspace_model.Write((fs::path(root_) / "sparse").string());
}

void DenseWorkspace::WriteConfigs(const std::vector<std::string>& image_names,
                                  int num_source_images) const {
  std::ofstream fusion(fs::path(root_) / "stereo" / "fusion.cfg");
  std::ofstream patch_match(fs::path(root_) / "stereo" / "patch-match.cfg");
  for (const std::string& name : image_names) {
    fusion << name << "\n";
    patch_match << name << "\n__auto__, " << num_source_images << "\n";
  }
  if (!fusion || !patch_match) {
    throw std::runtime_error("Cannot write the configuration files in " + root_ + "/stereo");
  }
}

void DenseWorkspace::CopyImage(const std::string& image_name,
                               const std::string& source_path) const {
  const std::string path = ImagePath(image_name);
  EnsureParent(path);
  fs::copy_file(source_path, path, fs::copy_options::overwrite_existing);
}

void DenseWorkspace::WriteImage(const std::string& image_name, const cv::Mat& image) const {
  const std::string path = ImagePath(image_name);
  EnsureParent(path);
  if (!cv::imwrite(path, image)) {
    throw std::runtime_error("Cannot write the image " + path);
  }
}

void DenseWorkspace::WriteDepthMap(const std::string& image_name, const cv::Mat& depth) const {
  if (depth.type() != CV_32F) {
    throw std::invalid_argument("WriteDepthMap: depth must be CV_32F");
  }
  colmap::mvs::DepthMap map(depth.cols, depth.rows, 0, 0);  // the range is not stored
  for (int row = 0; row < depth.rows; ++row) {
    for (int col = 0; col < depth.cols; ++col) {
      map.Set(row, col, depth.at<float>(row, col));
    }
  }
  const std::string path = DepthMapPath(image_name);
  EnsureParent(path);
  map.Write(path);
}

void DenseWorkspace::WriteNormalMap(const std::string& image_name, const cv::Mat& normals) const {
  if (normals.type() != CV_32FC3) {
    throw std::invalid_argument("WriteNormalMap: normals must be CV_32FC3");
  }
  colmap::mvs::NormalMap map(normals.cols, normals.rows);
  for (int row = 0; row < normals.rows; ++row) {
    for (int col = 0; col < normals.cols; ++col) {
      const cv::Vec3f& n = normals.at<cv::Vec3f>(row, col);
      for (int d = 0; d < 3; ++d) map.Set(row, col, d, n[d]);
    }
  }
  const std::string path = NormalMapPath(image_name);
  EnsureParent(path);
  map.Write(path);
}

std::vector<std::string> ReadFusionImageNames(const std::string& root) {
  const fs::path config = fs::path(root) / "stereo" / "fusion.cfg";
  std::ifstream file(config);
  if (!file) {
    throw std::runtime_error("Cannot read " + config.string() + " (not a dense workspace)");
  }
  std::vector<std::string> names;
  for (std::string line; std::getline(file, line);) {
    if (!line.empty()) names.push_back(line);
  }
  return names;
}

cv::Mat DenseWorkspace::ReadDepthMap(const std::string& image_name) const {
  return ReadColmapDepthMap(DepthMapPath(image_name));
}

cv::Mat DenseWorkspace::ReadNormalMap(const std::string& image_name) const {
  const std::string path = NormalMapPath(image_name);
  if (!fs::is_regular_file(path)) {
    throw std::runtime_error("No normal map at " + path);
  }
  CheckColmapMatrixFile(path, 3);
  colmap::mvs::NormalMap map;
  map.Read(path);
  if (map.GetDepth() != 3) {
    throw std::runtime_error("Not a normal map: " + path);
  }
  cv::Mat normals(static_cast<int>(map.GetHeight()), static_cast<int>(map.GetWidth()), CV_32FC3);
  for (int row = 0; row < normals.rows; ++row) {
    for (int col = 0; col < normals.cols; ++col) {
      cv::Vec3f& n = normals.at<cv::Vec3f>(row, col);
      for (int d = 0; d < 3; ++d) n[d] = map.Get(row, col, d);
    }
  }
  return normals;
}

}  // namespace colmap_lidar
