#include "colmap_ext/kitti_source.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

namespace colmap_lidar {

namespace fs = std::filesystem;

std::vector<std::pair<std::string, int>> SelectKittiFrames(const std::string& folder,
                                                           const KittiImportOptions& options) {
  if (!fs::is_directory(folder)) {
    throw std::runtime_error("no images of camera " + std::to_string(options.camera) + ": " +
                             folder + " does not exist");
  }
  std::vector<std::string> all;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() == ".png") all.push_back(entry.path().stem().string());
  }
  std::sort(all.begin(), all.end());
  std::vector<std::pair<std::string, int>> frames;
  for (const std::string& frame : all) {
    size_t used = 0;
    int index = -1;
    try {
      index = std::stoi(frame, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != frame.size() || index < 0) {
      throw std::runtime_error(folder + "/" + frame + ".png: not a KITTI frame name (digits only)");
    }
    if (index < options.first || (options.last >= 0 && index > options.last) ||
        (index - options.first) % options.step != 0) {
      continue;
    }
    frames.emplace_back(frame, index);
  }
  if (frames.empty()) throw std::runtime_error("no frames selected in " + folder);
  return frames;
}

void CheckKittiCloud(const std::string& path, const std::string& frame) {
  if (!fs::is_regular_file(path)) {
    throw std::runtime_error(path + ": frame " + frame + " has no Velodyne cloud");
  }
  const uintmax_t size = fs::file_size(path);
  if (size == 0 || size % 16 != 0) {
    throw std::runtime_error(path + ": truncated KITTI cloud (" + std::to_string(size) +
                             " bytes, not a whole number of 16-byte points)");
  }
}

std::vector<std::string> KittiRightImages(const std::string& right_folder,
                                          const std::vector<std::string>& frames,
                                          const KittiImportOptions& options) {
  if (!options.use_right || options.camera == 3) return {};
  std::vector<std::string> paths;
  for (const std::string& frame : frames) {
    paths.push_back((fs::path(right_folder) / (frame + ".png")).string());
    if (!fs::is_regular_file(paths.back())) return {};
  }
  return paths;
}

std::pair<int, int> KittiImageSize(const std::string& path) {
  const cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw std::runtime_error(path + ": cannot read the image");
  return {image.cols, image.rows};
}

}  // namespace colmap_lidar
