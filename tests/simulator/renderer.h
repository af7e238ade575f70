// Ray-cast rendering of a station's images and true depth, and of its LiDAR cloud.
#pragma once

#include "lidar/point_cloud.h"
#include "tests/simulator/scene.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"

#include <opencv2/core.hpp>

namespace colmap_lidar {
namespace sim {

struct ImageOptions {
  double pixel_noise = 1.0;  // std. dev. of additive Gaussian noise, grey levels of 255
  bool vignetting = false;   // cos^4 fall-off
  uint64_t seed = 0;
};

// 8-bit grey image through the camera (pixel centres at +0.5, as in COLMAP), and if `depth` is not null
// the true z-depth per pixel (CV_32F, 0 where the ray hits nothing).
cv::Mat RenderImage(const Scene& scene,
                    const colmap::Camera& camera,
                    const colmap::Rigid3d& cam_from_world,
                    const ImageOptions& options,
                    cv::Mat* depth);

struct LidarOptions {
  size_t num_points = 1600000;  // rays per station (the seed's 20 s accumulation gives ~1.6 M)
  double range_noise_m = 0.01;  // std. dev. along the ray
  double max_range_m = 100;
  bool mixed_edge_points =
      false;  // returns averaged across depth discontinuities, as real VLP-16s do
  uint64_t seed = 0;
};

// A VLP-16 (16 beams over +-15 deg, 2 deg apart) spinning about its z axis while a motor turns it about
// the LiDAR frame's x axis through 180 deg, so that the accumulated cloud covers the full sphere.
// Points are returned in the LiDAR frame (point_in_lidar) with intensity = 255 * albedo * |cos|.
PointCloud ScanLidar(const Scene& scene,
                     const colmap::Rigid3d& world_from_lidar,
                     const LidarOptions& options);

}  // namespace sim
}  // namespace colmap_lidar
