#include "bridge/simulation/renderer.h"

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace colmap_lidar {
namespace sim {

namespace {

// Grey value of the scene along the ray through `image_point` (0 for the sky), and its hit distance.
double RayRadiance(const Scene& scene,
                   const colmap::Camera& camera,
                   const colmap::Rigid3d& world_from_cam,
                   const Eigen::Vector2d& image_point,
                   RayHit* hit) {
  const Eigen::Vector3d ray = camera.CamFromImg(image_point).homogeneous();
  const Eigen::Vector3d direction = (world_from_cam.rotation * ray).normalized();
  if (!scene.Intersect(world_from_cam.translation, direction, 1e3, hit)) return 0;
  return scene.Shade(world_from_cam.translation + hit->t * direction, hit->normal, hit->primitive);
}

}  // namespace

cv::Mat RenderImage(const Scene& scene,
                    const colmap::Camera& camera,
                    const colmap::Rigid3d& cam_from_world,
                    const ImageOptions& options,
                    cv::Mat* depth) {
  const int width = static_cast<int>(camera.width);
  const int height = static_cast<int>(camera.height);
  const int n = options.samples_per_axis;
  cv::Mat image(height, width, CV_8UC1);
  if (depth) depth->create(height, width, CV_32F);
  const colmap::Rigid3d world_from_cam = colmap::Inverse(cam_from_world);
#pragma omp parallel for schedule(dynamic, 8)
  for (int row = 0; row < height; ++row) {
    std::mt19937_64 rng(options.seed * 1000003ull + row);
    std::normal_distribution<double> noise(0, options.pixel_noise);
    std::uniform_real_distribution<double> jitter(0, 1);
    for (int col = 0; col < width; ++col) {
      const Eigen::Vector2d centre(col + 0.5, row + 0.5);
      RayHit hit;
      double value = RayRadiance(scene, camera, world_from_cam, centre, &hit);
      const float z =
          hit.primitive >= 0  // z-depth along the optical axis
              ? static_cast<float>(hit.t / camera.CamFromImg(centre).homogeneous().norm())
              : 0.f;
      if (n > 1) {  // the pixel's area: n x n jittered strata, their mean
        value = 0;
        for (int k = 0; k < n * n; ++k) {
          const double jitter_x = jitter(rng);  // drawn in a fixed order: the same image everywhere
          const double jitter_y = jitter(rng);
          const Eigen::Vector2d offset((k % n + jitter_x) / n, (k / n + jitter_y) / n);
          RayHit sample;
          value += RayRadiance(
                       scene, camera, world_from_cam, Eigen::Vector2d(col, row) + offset, &sample) /
                   (n * n);
        }
      }
      if (options.vignetting) {
        value *= std::pow(1.0 / camera.CamFromImg(centre).homogeneous().norm(), 4);
      }
      if (options.pixel_noise > 0) value += noise(rng);
      image.at<uint8_t>(row, col) = static_cast<uint8_t>(std::clamp(std::lround(value), 0l, 255l));
      if (depth) depth->at<float>(row, col) = z;
    }
  }
  return image;
}

namespace {

// The parts' points and intensities, in order.
PointCloud Concatenated(const std::vector<PointCloud>& parts) {
  PointCloud cloud;
  size_t total = 0;
  for (const PointCloud& part : parts) total += part.Size();
  cloud.Reserve(total, false, false, true);
  for (const PointCloud& part : parts) {
    cloud.points.insert(cloud.points.end(), part.points.begin(), part.points.end());
    cloud.intensities.insert(
        cloud.intensities.end(), part.intensities.begin(), part.intensities.end());
  }
  return cloud;
}

}  // namespace

PointCloud ScanLidar(const Scene& scene,
                     const colmap::Rigid3d& world_from_lidar,
                     const LidarOptions& options) {
  constexpr int kNumBeams = 16;
  // Azimuth samples per revolution (1800 = 0.2 deg at full density) and motor positions over 180 deg.
  const double per_beam = static_cast<double>(options.num_points) / kNumBeams;
  const int num_azimuths =
      std::clamp(static_cast<int>(std::lround(std::sqrt(per_beam * 20))), 60, 1800);
  const int num_motor_steps = std::max(2, static_cast<int>(std::ceil(per_beam / num_azimuths)));
  const Eigen::Matrix3d world_from_lidar_rotation = world_from_lidar.rotation.toRotationMatrix();
  std::vector<PointCloud> per_step(num_motor_steps);
#pragma omp parallel for schedule(dynamic, 1)
  for (int m = 0; m < num_motor_steps; ++m) {
    std::mt19937_64 rng(options.seed * 7919ull + m);
    std::normal_distribution<double> noise(0, options.range_noise_m);
    std::uniform_real_distribution<double> unit(0, 1);
    const double motor = M_PI * (m + 0.5) / num_motor_steps;
    const Eigen::Matrix3d lidar_from_head =
        Eigen::AngleAxisd(motor, Eigen::Vector3d::UnitX()).toRotationMatrix();
    PointCloud& cloud = per_step[m];
    cloud.Reserve(kNumBeams * num_azimuths, false, false, true);
    for (int a = 0; a < num_azimuths; ++a) {
      const double azimuth = 2 * M_PI * (a + 0.37 * m) / num_azimuths;
      for (int b = 0; b < kNumBeams; ++b) {
        const double elevation = (-15.0 + 2.0 * b) * M_PI / 180.0;
        const Eigen::Vector3d ray_in_head(std::cos(elevation) * std::cos(azimuth),
                                          std::cos(elevation) * std::sin(azimuth),
                                          std::sin(elevation));
        const Eigen::Vector3d ray_in_lidar = lidar_from_head * ray_in_head;
        const Eigen::Vector3d ray_in_world = world_from_lidar_rotation * ray_in_lidar;
        RayHit hit;
        if (!scene.Intersect(
                world_from_lidar.translation, ray_in_world, options.max_range_m, &hit)) {
          continue;
        }
        double range = hit.t;
        if (options.mixed_edge_points) {
          // A second ray 0.17 deg away stands in for the beam's footprint: across a depth edge the
          // sensor reports the average of both returns ("mixed pixels") about a third of the time.
          const Eigen::Vector3d offset_ray =
              (ray_in_world + 0.003 * ray_in_world.cross(Eigen::Vector3d::UnitZ())).normalized();
          RayHit other;
          if (scene.Intersect(
                  world_from_lidar.translation, offset_ray, options.max_range_m, &other) &&
              std::abs(other.t - hit.t) > 0.1 && unit(rng) < 0.35) {
            range = 0.5 * (hit.t + other.t);
          }
        }
        const Eigen::Vector3d point_in_world = world_from_lidar.translation + hit.t * ray_in_world;
        const double cos_incidence = std::abs(hit.normal.dot(ray_in_world));
        if (options.range_noise_m > 0) range += noise(rng);
        cloud.points.push_back(range * ray_in_lidar);
        cloud.intensities.push_back(static_cast<float>(
            255.0 * scene.Albedo(point_in_world, hit.primitive) * cos_incidence));
      }
    }
  }
  return Concatenated(per_step);
}

colmap::Rigid3d Interpolate(const colmap::Rigid3d& a, const colmap::Rigid3d& b, double tau) {
  return colmap::Rigid3d(a.rotation.slerp(tau, b.rotation),
                         (1 - tau) * a.translation + tau * b.translation);
}

PointCloud ScanSweep(const Scene& scene,
                     const std::function<colmap::Rigid3d(double)>& world_from_lidar_at,
                     const LidarOptions& options) {
  constexpr int kNumBeams = 64;
  const int num_azimuths = std::max(60, static_cast<int>(options.num_points / kNumBeams));
  std::vector<PointCloud> per_column(num_azimuths);
#pragma omp parallel for schedule(dynamic, 64)
  for (int a = 0; a < num_azimuths; ++a) {
    std::mt19937_64 rng(options.seed * 7919ull + a);
    std::normal_distribution<double> noise(0, options.range_noise_m);
    const double tau = (a + 0.5) / num_azimuths;
    const colmap::Rigid3d world_from_lidar = world_from_lidar_at(tau);
    const Eigen::Matrix3d rotation = world_from_lidar.rotation.toRotationMatrix();
    const double azimuth = M_PI + 2 * M_PI * tau;
    for (int b = 0; b < kNumBeams; ++b) {
      const double elevation = (2.0 - 26.8 * b / (kNumBeams - 1)) * M_PI / 180.0;
      const Eigen::Vector3d ray_in_lidar(std::cos(elevation) * std::cos(azimuth),
                                         std::cos(elevation) * std::sin(azimuth),
                                         std::sin(elevation));
      const Eigen::Vector3d ray_in_world = rotation * ray_in_lidar;
      RayHit hit;
      if (!scene.Intersect(world_from_lidar.translation, ray_in_world, options.max_range_m, &hit)) {
        continue;
      }
      const Eigen::Vector3d point_in_world = world_from_lidar.translation + hit.t * ray_in_world;
      double range = hit.t;
      if (options.range_noise_m > 0) range += noise(rng);
      per_column[a].points.push_back(range * ray_in_lidar);
      per_column[a].intensities.push_back(
          static_cast<float>(255.0 * scene.Albedo(point_in_world, hit.primitive) *
                             std::abs(hit.normal.dot(ray_in_world))));
    }
  }
  PointCloud cloud;
  for (const PointCloud& column : per_column) {
    cloud.points.insert(cloud.points.end(), column.points.begin(), column.points.end());
    cloud.intensities.insert(
        cloud.intensities.end(), column.intensities.begin(), column.intensities.end());
  }
  return cloud;
}

}  // namespace sim
}  // namespace colmap_lidar
