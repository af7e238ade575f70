#include "colmap_ext/stereo_depth_files.h"

#include "colmap_ext/logging.h"
#include "lidar/util/atomic_file.h"

#include "colmap/mvs/depth_map.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// Inverse depth between the 2nd and 98th percentile, turbo colour map, black = no depth.
cv::Mat DepthPreview(const cv::Mat& depth) {
  std::vector<float> inverse;
  for (int row = 0; row < depth.rows; ++row) {
    for (int col = 0; col < depth.cols; ++col) {
      const float z = depth.at<float>(row, col);
      if (z > 0.f) inverse.push_back(1.f / z);
    }
  }
  cv::Mat grey(depth.size(), CV_8U, cv::Scalar(0));
  if (!inverse.empty()) {
    std::sort(inverse.begin(), inverse.end());
    const float lo = inverse[inverse.size() * 2 / 100];
    const float hi = inverse[inverse.size() * 98 / 100];
    for (int row = 0; row < depth.rows; ++row) {
      for (int col = 0; col < depth.cols; ++col) {
        const float z = depth.at<float>(row, col);
        if (z <= 0.f) continue;
        const float t = (1.f / z - lo) / std::max(hi - lo, 1e-9f);
        grey.at<uchar>(row, col) =
            static_cast<uchar>(std::lround(1 + 254 * std::clamp(t, 0.f, 1.f)));
      }
    }
  }
  cv::Mat preview;
  cv::applyColorMap(grey, preview, cv::COLORMAP_TURBO);
  preview.setTo(cv::Scalar(0, 0, 0), grey == 0);
  return preview;
}

}  // namespace

std::string StereoDepthMapPath(const std::string& depth_path, const std::string& station) {
  return (fs::path(depth_path) / "depth_maps" / (station + ".png.geometric.bin")).string();
}

void WriteStationStereoDepth(const std::string& output_path,
                             const std::string& station,
                             const StereoDepth& depth) {
  const fs::path root(output_path);
  for (const char* folder : {"depth_maps", "confidence_maps", "previews"}) {
    fs::create_directories(root / folder);
  }
  float max_depth = 0.f;
  for (int row = 0; row < depth.depth.rows; ++row) {
    for (int col = 0; col < depth.depth.cols; ++col) {
      max_depth = std::max(max_depth, depth.depth.at<float>(row, col));
    }
  }
  colmap::mvs::DepthMap depth_map(depth.depth.cols, depth.depth.rows, 0.f, max_depth);
  for (int row = 0; row < depth.depth.rows; ++row) {
    for (int col = 0; col < depth.depth.cols; ++col) {
      depth_map.Set(row, col, depth.depth.at<float>(row, col));
    }
  }
  WriteAtomically(StereoDepthMapPath(output_path, station), [&](const std::string& path) {
    depth_map.Write(path);
    return fs::exists(path) && fs::file_size(path) > 0;
  });

  const auto write_png = [](const cv::Mat& image) {
    return [&image](const std::string& path) { return cv::imwrite(path, image); };
  };
  WriteAtomically((root / "confidence_maps" / (station + ".png")).string(),
                  write_png(depth.confidence));

  WriteAtomically((root / "previews" / (station + ".png")).string(),
                  write_png(DepthPreview(depth.depth)));
}

StereoDepthInfo ReadStereoDepthInfo(const std::string& depth_path) {
  const std::string path = (fs::path(depth_path) / "stereo.json").string();
  std::ifstream file(path);
  if (!file) {
    throw std::runtime_error("no stereo.json in " + depth_path +
                             ": run `colmap-lidar stereo_depth --output_path " + depth_path +
                             "` first");
  }
  try {
    const nlohmann::json json = nlohmann::json::parse(file);
    StereoDepthInfo info;
    info.rectified_focal_px = json.at("rectified_focal_px").get<double>();
    info.baseline_m = json.at("baseline_m").get<double>();
    THROW_CHECK_GT(info.rectified_focal_px, 0) << path;
    THROW_CHECK_GT(info.baseline_m, 0) << path;
    return info;
  } catch (const nlohmann::json::exception& error) {
    throw std::runtime_error(path + ": " + error.what());
  }
}

void WriteStereoDepthInfo(const std::string& output_path,
                          const StereoDepthInfo& info,
                          const StereoDepthOptions& options) {
  nlohmann::json json;
  json["rectified_focal_px"] = info.rectified_focal_px;
  json["baseline_m"] = info.baseline_m;
  json["depth"] = "z in the original left camera, metres; 0 = no depth";
  json["min_disparity_px"] = info.min_disparity_px;
  json["num_disparities"] = info.num_disparities;
  json["options"] = {{"mode", options.mode},
                     {"min_depth_m", options.min_depth_m},
                     {"max_depth_m", options.max_depth_m},
                     {"vertically_symmetric", options.vertically_symmetric},
                     {"block_size", options.block_size},
                     {"p1_factor", options.p1_factor},
                     {"p2_factor", options.p2_factor},
                     {"uniqueness_ratio", options.uniqueness_ratio},
                     {"speckle_window_size", options.speckle_window_size},
                     {"speckle_range_px", options.speckle_range_px},
                     {"max_left_right_diff_px", options.max_left_right_diff_px},
                     {"mirrored_left_right_check", options.mirrored_left_right_check}};
  for (const auto& [station, fraction] : info.valid_fraction) {
    json["valid_fraction"][station] = fraction;
  }
  WriteFileAtomically((fs::path(output_path) / "stereo.json").string(), json.dump(2) + "\n");
}

}  // namespace colmap_lidar
