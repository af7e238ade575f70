#include "bridge/joint/camera_centre_observations.h"

#include "lidar/util/statistics.h"

#include <cmath>
#include <utility>

namespace colmap_lidar {
namespace {

struct ObservationDepth {
  colmap::image_t image_id;
  colmap::point2D_t point2D_idx;
  double depth;
};

std::vector<ObservationDepth> ObservationDepths(const colmap::Reconstruction& reconstruction) {
  std::vector<ObservationDepth> depths;
  for (const auto& [point3D_id, point3D] : reconstruction.Points3D()) {
    for (const colmap::TrackElement& element : point3D.track.Elements()) {
      const colmap::Image& image = reconstruction.Image(element.image_id);
      const double depth = (image.CamFromWorld() * point3D.xyz).z();
      depths.push_back({element.image_id, element.point2D_idx, depth});
    }
  }
  return depths;
}

}  // namespace

std::vector<std::pair<colmap::image_t, colmap::point2D_t>> ObservationsAtCameraCentres(
    const colmap::Reconstruction& reconstruction, const double min_relative_depth) {
  const std::vector<ObservationDepth> depths = ObservationDepths(reconstruction);
  std::vector<std::pair<colmap::image_t, colmap::point2D_t>> at_centres;
  if (depths.empty()) return at_centres;
  std::vector<double> absolute;
  absolute.reserve(depths.size());
  for (const ObservationDepth& observation : depths)
    absolute.push_back(std::abs(observation.depth));
  const double min_depth = min_relative_depth * Median(std::move(absolute));
  for (const ObservationDepth& observation : depths) {
    if (std::abs(observation.depth) < min_depth) {
      at_centres.emplace_back(observation.image_id, observation.point2D_idx);
    }
  }
  return at_centres;
}

}  // namespace colmap_lidar
