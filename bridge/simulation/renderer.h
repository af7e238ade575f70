// Ray-cast rendering of a station's images and true depth, and of its LiDAR cloud.
#pragma once

#include "bridge/simulation/scene.h"
#include "lidar/point_cloud.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"

#include <opencv2/core.hpp>

#include <functional>

namespace colmap_lidar {
namespace sim {

struct ImageOptions {
  // std. dev. of additive Gaussian noise, grey levels of 255
  double pixel_noise = 1.0;
  // cos^4 fall-off
  bool vignetting = false;
  // A pixel integrates light over its area: the mean of samples_per_axis^2 rays jittered in as many
  // strata of the pixel (1: one ray through its centre). One ray aliases texture finer than the
  // pixel's footprint, which on a surface seen at a grazing angle (a road ahead) is several
  // centimetres long; aliased texture moves unlike the surface, and keypoints on it are biased.
  int samples_per_axis = 1;
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
  // rays per station (Zhen et al. 2019: a 20 s accumulation gives ~1.6 M)
  size_t num_points = 1600000;
  // std. dev. along the ray
  double range_noise_m = 0.01;
  double max_range_m = 100;
  // returns averaged across depth discontinuities, as real VLP-16s do
  bool mixed_edge_points = false;
  uint64_t seed = 0;
};

// A VLP-16 (16 beams over +-15 deg, 2 deg apart) spinning about its z axis while a motor turns it about
// the LiDAR frame's x axis through 180 deg, so that the accumulated cloud covers the full sphere.
// Points are returned in the LiDAR frame (point_in_lidar) with intensity = 255 * albedo * |cos|.
PointCloud ScanLidar(const Scene& scene,
                     const colmap::Rigid3d& world_from_lidar,
                     const LidarOptions& options);

// One sweep of a spinning 64-beam LiDAR (HDL-64-like: elevations +2 to -24.8 deg) on a moving
// platform, without motion compensation: the column fired at fraction tau in [0, 1] of the sweep sees
// the scene from world_from_lidar_at(tau), and its points are returned in the LiDAR frame of that
// instant (point_in_lidar, as a real sensor's driver writes them). The sweep starts and ends looking
// backwards (azimuth 180 deg) and faces forward at tau = 0.5, when the camera is triggered (KITTI's
// convention): the frame's pose is world_from_lidar_at(0.5). options.num_points rays in all.
PointCloud ScanSweep(const Scene& scene,
                     const std::function<colmap::Rigid3d(double)>& world_from_lidar_at,
                     const LidarOptions& options);

// Rotation slerped, translation interpolated linearly, tau in [0, 1].
colmap::Rigid3d Interpolate(const colmap::Rigid3d& a, const colmap::Rigid3d& b, double tau);

}  // namespace sim
}  // namespace colmap_lidar
