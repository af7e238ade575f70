#include "bridge/survey/surface_world.h"

#include "lidar/kd_tree.h"
#include "lidar/spherical_range_image.h"
#include "lidar/util/statistics.h"
#include "lidar/voxel_accumulator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <random>
#include <stdexcept>
#include <tuple>
#include <unordered_set>

namespace colmap_lidar {
namespace sim {
namespace {

// The z-buffers of one surface, built once per viewpoint.
class SurfaceViews {
 public:
  // `spacing`: the surface's median point spacing (> 0).
  SurfaceViews(std::shared_ptr<const PointCloud> surface, double spacing)
      : surface_(std::move(surface)), spacing_(spacing) {}

  // The surface's points about `center` (nearest per cell), and the image's cell size.
  std::shared_ptr<const SphericalRangeImage> View(const Eigen::Vector3d& center) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto key = std::make_tuple(center.x(), center.y(), center.z());
    auto it = views_.find(key);
    if (it != views_.end()) return it->second;
    std::vector<Eigen::Vector3d> relative(surface_->Size());
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < relative.size(); ++i) {
      relative[i] = surface_->points[i] - center;
      nearest = std::min(nearest, relative[i].norm());
    }
    const double resolution = 3 * spacing_ / std::max(nearest, 0.1);
    auto view = std::make_shared<const SphericalRangeImage>(relative, resolution, 0.0);
    views_[key] = view;
    return view;
  }

  const PointCloud& Surface() const { return *surface_; }

 private:
  std::shared_ptr<const PointCloud> surface_;
  double spacing_ = 0;
  std::mutex mutex_;
  std::map<std::tuple<double, double, double>, std::shared_ptr<const SphericalRangeImage>> views_;
};

bool Visible(SurfaceViews* views, const Eigen::Vector3d& center, const Eigen::Vector3d& point) {
  const auto view = views->View(center);
  const Eigen::Vector3d relative = point - center;
  int row = 0, col = 0;
  view->CellOf(relative, &row, &col);
  const double nearest = view->Range(row, col);
  const double range = relative.norm();
  return nearest == 0 || range <= nearest + 0.02 + 0.01 * range;
}

// The nearest return per cell about the LiDAR: a surface point or the ground plane at ground_z (up
// to kGroundRadiusM away), with range noise. The ground is thinned evenly to keep at most num_points
// in all; the structure keeps every cell (a real scanner sees it densely from a few metres).
constexpr double kGroundRadiusM = 30;

PointCloud Scan(SurfaceViews* views,
                double ground_z,
                const colmap::Rigid3d& world_from_lidar,
                const LidarOptions& options) {
  const Eigen::Vector3d center = world_from_lidar.translation;
  const auto view = views->View(center);
  const Eigen::Matrix3d lidar_from_world = world_from_lidar.rotation.inverse().toRotationMatrix();
  std::mt19937 rng(static_cast<uint32_t>(options.seed));
  std::normal_distribution<double> noise(0, options.range_noise_m);
  std::vector<Eigen::Vector3d> structure, ground;
  const double resolution = view->Resolution();
  const int last_row = std::max(view->FirstRow() + view->NumRows(), int(M_PI / 2 / resolution));
  for (int row = 0; row < last_row; ++row) {
    const double elevation = (row + 0.5) * resolution - M_PI / 2;
    for (int col = 0; col < view->NumCols(); ++col) {
      const double azimuth = (col + 0.5) * resolution - M_PI;
      const Eigen::Vector3d direction(std::cos(elevation) * std::cos(azimuth),
                                      std::cos(elevation) * std::sin(azimuth),
                                      std::sin(elevation));
      double range = std::numeric_limits<double>::infinity();
      Eigen::Vector3d ray;
      const int64_t index = view->Index(row, col);
      if (index >= 0) ray = views->Surface().points[index] - center, range = ray.norm();
      const double to_ground = direction.z() < 0 ? (ground_z - center.z()) / direction.z() : -1;
      const bool on_ground = to_ground > 0 && to_ground < range &&
                             (to_ground * direction).head<2>().norm() < kGroundRadiusM;
      if (on_ground) ray = to_ground * direction, range = to_ground;
      if (!(range <= options.max_range_m) || range < 0.3) continue;
      (on_ground ? ground : structure)
          .push_back(lidar_from_world * (ray * (1 + noise(rng) / range)));
    }
  }
  PointCloud scan;
  scan.points = std::move(structure);
  const size_t room = options.num_points > scan.Size() ? options.num_points - scan.Size() : 1;
  const size_t stride = std::max<size_t>(1, (ground.size() + room - 1) / room);
  for (size_t i = 0; i < ground.size(); i += stride) scan.points.push_back(ground[i]);
  return scan;
}

// One point of the surface per voxel (the first): real surface points, where a voxel's centroid would
// lie inside the structure at its edges and be hidden by its own surface.
PointCloud FirstPointPerVoxel(const PointCloud& surface, double voxel) {
  std::unordered_set<uint64_t> seen;
  PointCloud thinned;
  for (const Eigen::Vector3d& p : surface.points) {
    if (seen.insert(VoxelKey(p, voxel)).second) thinned.points.push_back(p);
  }
  return thinned;
}

}  // namespace

double MedianPointSpacing(const PointCloud& cloud) {
  if (cloud.Size() < 2) return 0;
  const KdTree3 tree(cloud.points);
  std::vector<double> distances;
  const size_t step = std::max<size_t>(1, cloud.Size() / 2000);
  std::vector<size_t> indices;
  std::vector<double> squared;
  for (size_t i = 0; i < cloud.Size(); i += step) {
    tree.KNearest(cloud.points[i], 2, &indices, &squared);
    if (squared.size() == 2) distances.push_back(std::sqrt(squared[1]));
  }
  if (distances.empty()) return 0;
  return Median(std::move(distances));
}

SyntheticWorld WorldOfSurface(std::shared_ptr<const PointCloud> surface, double ground_z) {
  size_t finite = 0;
  for (const Eigen::Vector3d& p : surface->points) finite += p.allFinite();
  if (finite < 100 || finite != surface->Size()) {
    throw std::invalid_argument("The surface needs at least 100 points, all finite (" +
                                std::to_string(finite) + " of " + std::to_string(surface->Size()) +
                                " finite)");
  }
  const double spacing = MedianPointSpacing(*surface);
  if (!(spacing > 0)) {
    throw std::invalid_argument(
        "The surface's points lie on top of each other (median spacing 0): remove the duplicates");
  }
  auto views = std::make_shared<SurfaceViews>(surface, spacing);
  SyntheticWorld world;
  world.sample_surface = [surface](double spacing) {
    return FirstPointPerVoxel(*surface, spacing);
  };
  world.visible = [views](const Eigen::Vector3d& center, const Eigen::Vector3d& point) {
    return Visible(views.get(), center, point);
  };
  world.scan = [views, ground_z](const colmap::Rigid3d& world_from_lidar,
                                 const LidarOptions& options) {
    return Scan(views.get(), ground_z, world_from_lidar, options);
  };
  return world;
}

}  // namespace sim
}  // namespace colmap_lidar
