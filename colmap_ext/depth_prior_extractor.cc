#include "colmap_ext/depth_prior_extractor.h"

#include "colmap_ext/logging.h"
#include "colmap_ext/stereo_depth_files.h"

#include "colmap/scene/database.h"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>

namespace colmap_lidar {

namespace fs = std::filesystem;

bool DepthPriorOptions::Check() const {
  CHECK_OPTION_GE(max_radius_px, 0);
  CHECK_OPTION_GT(sigma_pixels, 0);
  CHECK_OPTION_GE(max_relative_jump, 0);
  return true;
}

std::optional<double> DepthAtKeypoint(const colmap::mvs::DepthMap& depth_map,
                                      double x,
                                      double y,
                                      const DepthPriorOptions& options) {
  const int width = static_cast<int>(depth_map.GetWidth());
  const int height = static_cast<int>(depth_map.GetHeight());
  const auto depth_at = [&](int col, int row) -> double {
    if (col < 0 || row < 0 || col >= width || row >= height) return 0;
    return depth_map.Get(row, col);
  };
  // Pixel centres are at (col + 0.5, row + 0.5).
  const double u = x - 0.5, v = y - 0.5;
  const int c0 = static_cast<int>(std::floor(u));
  const int r0 = static_cast<int>(std::floor(v));
  const double d00 = depth_at(c0, r0), d10 = depth_at(c0 + 1, r0), d01 = depth_at(c0, r0 + 1),
               d11 = depth_at(c0 + 1, r0 + 1);
  const double lo = std::min(std::min(d00, d10), std::min(d01, d11));
  const double hi = std::max(std::max(d00, d10), std::max(d01, d11));
  if (lo > 0 && hi - lo <= options.max_relative_jump * lo) {
    const double fu = u - c0, fv = v - r0;
    return (1 - fv) * ((1 - fu) * d00 + fu * d10) + fv * ((1 - fu) * d01 + fu * d11);
  }
  const int radius = static_cast<int>(std::ceil(options.max_radius_px));
  double best_distance_sq = options.max_radius_px * options.max_radius_px;
  std::optional<double> best;
  const int col_center = static_cast<int>(std::floor(x));
  const int row_center = static_cast<int>(std::floor(y));
  for (int row = row_center - radius; row <= row_center + radius; ++row) {
    for (int col = col_center - radius; col <= col_center + radius; ++col) {
      const double depth = depth_at(col, row);
      if (depth <= 0) continue;
      const double dx = col + 0.5 - x, dy = row + 0.5 - y;
      const double distance_sq = dx * dx + dy * dy;
      if (distance_sq <= best_distance_sq) {
        best_distance_sq = distance_sq;
        best = depth;
      }
    }
  }
  return best;
}

double DepthSigma(double depth, double baseline_m, double focal_px, double sigma_pixels) {
  // Zhen et al. 2019: sigma_d = d^2 / (b f) * sigma_p.
  return depth * depth / (baseline_m * focal_px) * sigma_pixels;
}

std::vector<DepthPrior> ExtractDepthPriors(const colmap::FeatureKeypoints& keypoints,
                                           const colmap::mvs::DepthMap& depth_map,
                                           double baseline_m,
                                           double focal_px,
                                           const DepthPriorOptions& options) {
  std::vector<DepthPrior> priors;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const std::optional<double> depth =
        DepthAtKeypoint(depth_map, keypoints[i].x, keypoints[i].y, options);
    if (!depth) continue;
    DepthPrior prior;
    prior.point2D_idx = static_cast<colmap::point2D_t>(i);
    prior.depth = *depth;
    prior.sigma = DepthSigma(*depth, baseline_m, focal_px, options.sigma_pixels);
    priors.push_back(prior);
  }
  return priors;
}

namespace {

// The stereo depth map at `map_path`, which must be in `image`'s pixel grid (else every prior
// would be read at the wrong place).
colmap::mvs::DepthMap ReadDepthMapOfImage(const std::string& map_path,
                                          const colmap::Image& image,
                                          const colmap::Camera& camera) {
  colmap::mvs::DepthMap depth_map;
  depth_map.Read(map_path);
  THROW_CHECK_GT(depth_map.GetWidth(), 0) << "cannot read " << map_path;
  if (depth_map.GetWidth() != camera.width || depth_map.GetHeight() != camera.height) {
    throw std::runtime_error(map_path + " is " + std::to_string(depth_map.GetWidth()) + "x" +
                             std::to_string(depth_map.GetHeight()) + " but image " + image.Name() +
                             " is " + std::to_string(camera.width) + "x" +
                             std::to_string(camera.height) +
                             ": the depth maps belong to another dataset or rig");
  }
  return depth_map;
}

}  // namespace

std::vector<ImageDepthPriorCount> ExtractDatabaseDepthPriors(const std::string& database_path,
                                                             const std::string& depth_path,
                                                             const DepthPriorOptions& options) {
  THROW_CHECK(options.Check());
  THROW_CHECK(fs::is_regular_file(database_path))
      << "Database file does not exist: " << database_path;
  const StereoDepthInfo info = ReadStereoDepthInfo(depth_path);
  // Our connection first: it rejects a non-COLMAP file before COLMAP would create tables in it.
  ExtensionDatabase extension(database_path);
  std::vector<colmap::Image> images;
  std::map<colmap::image_t, colmap::FeatureKeypoints> keypoints;
  std::map<colmap::camera_t, colmap::Camera> cameras;
  {
    const colmap::Database database(database_path);
    images = database.ReadAllImages();
    for (const colmap::Image& image : images) {
      keypoints[image.ImageId()] = database.ReadKeypoints(image.ImageId());
    }
    for (const colmap::Camera& camera : database.ReadAllCameras()) {
      cameras[camera.camera_id] = camera;
    }
  }
  std::sort(images.begin(), images.end(), [](const colmap::Image& a, const colmap::Image& b) {
    return a.Name() < b.Name();
  });
  std::vector<ImageDepthPriorCount> counts;
  std::map<colmap::image_t, std::vector<DepthPrior>> priors;
  for (const colmap::Image& image : images) {
    ImageDepthPriorCount count;
    count.image_name = image.Name();
    count.num_keypoints = keypoints.at(image.ImageId()).size();
    const std::string stem = fs::path(image.Name()).stem().string();
    const std::string map_path = StereoDepthMapPath(depth_path, stem);
    count.has_depth_map = fs::is_regular_file(map_path);
    if (count.has_depth_map) {
      const colmap::mvs::DepthMap depth_map =
          ReadDepthMapOfImage(map_path, image, cameras.at(image.CameraId()));
      std::vector<DepthPrior>& image_priors = priors[image.ImageId()];
      image_priors = ExtractDepthPriors(keypoints.at(image.ImageId()),
                                        depth_map,
                                        info.baseline_m,
                                        info.rectified_focal_px,
                                        options);
      count.num_priors = image_priors.size();
      std::cout << "  " << image.Name() << ": " << count.num_priors << " of " << count.num_keypoints
                << " keypoints with a depth prior (" << std::fixed << std::setprecision(1)
                << 100.0 * count.num_priors / std::max<size_t>(1, count.num_keypoints) << " %)"
                << std::endl;
    } else {
      std::cout << "  " << image.Name() << ": no depth map (" << map_path << "), no priors"
                << std::endl;
    }
    counts.push_back(count);
  }
  extension.WriteDepthPriors(priors);
  return counts;
}

}  // namespace colmap_lidar
