#include "bridge/joint/landmark_lidar_term.h"

#include <cmath>
#include <limits>

namespace colmap_lidar {

std::vector<LandmarkPlaneObservation> AssociateLandmarksWithLidar(
    const colmap::Reconstruction& reconstruction,
    const std::map<colmap::image_t, const StationCloud*>& clouds,
    const colmap::Rigid3d& cam_from_lidar,
    double max_distance,
    double max_curvature) {
  std::vector<std::pair<colmap::image_t, const StationCloud*>> images;
  for (const auto& [image_id, cloud] : clouds) {
    if (reconstruction.ExistsImage(image_id) && reconstruction.Image(image_id).IsRegistered()) {
      images.emplace_back(image_id, cloud);
    }
  }
  const colmap::Rigid3d lidar_from_cam = colmap::Inverse(cam_from_lidar);
  const double max_squared = max_distance * max_distance;
  std::vector<std::vector<LandmarkPlaneObservation>> per_image(images.size());
#pragma omp parallel for schedule(dynamic)
  for (int k = 0; k < static_cast<int>(images.size()); ++k) {
    const auto [image_id, station] = images[k];
    const colmap::Image& image = reconstruction.Image(image_id);
    const colmap::Rigid3d lidar_from_world = lidar_from_cam * image.CamFromWorld();
    for (const colmap::Point2D& point2D : image.Points2D()) {
      if (!point2D.HasPoint3D()) continue;
      const Eigen::Vector3d landmark_in_lidar =
          lidar_from_world * reconstruction.Point3D(point2D.point3D_id).xyz;
      size_t index = 0;
      double squared = 0;
      if (!station->tree->Nearest(landmark_in_lidar, &index, &squared) || squared > max_squared ||
          station->curvature[index] > max_curvature ||
          station->cloud.normals[index].squaredNorm() < 0.5) {
        continue;
      }
      per_image[k].push_back({image_id,
                              point2D.point3D_id,
                              station->cloud.points[index],
                              station->cloud.normals[index].normalized(),
                              false});
    }
  }
  std::vector<LandmarkPlaneObservation> observations;
  for (auto& image : per_image) observations.insert(observations.end(), image.begin(), image.end());
  return observations;
}

double LandmarkPlaneDistance(const LandmarkPlaneObservation& observation,
                             const colmap::Reconstruction& reconstruction,
                             const colmap::Rigid3d& cam_from_lidar) {
  if (!reconstruction.ExistsPoint3D(observation.point3D_id) ||
      !reconstruction.ExistsImage(observation.image_id)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const Eigen::Vector3d landmark_in_lidar =
      colmap::Inverse(cam_from_lidar) * (reconstruction.Image(observation.image_id).CamFromWorld() *
                                         reconstruction.Point3D(observation.point3D_id).xyz);
  return observation.normal_in_lidar.dot(landmark_in_lidar - observation.point_in_lidar);
}

std::array<LandmarkPlaneFacing, 3> SummariseByFacingAxis(
    const std::vector<LandmarkPlaneObservation>& observations,
    const colmap::Reconstruction& reconstruction,
    const colmap::Rigid3d& cam_from_lidar) {
  std::array<LandmarkPlaneFacing, 3> facing;
  std::array<double, 3> sum = {0, 0, 0}, squares = {0, 0, 0};
  for (const LandmarkPlaneObservation& observation : observations) {
    if (observation.outlier) continue;
    const double residual = LandmarkPlaneDistance(observation, reconstruction, cam_from_lidar);
    if (!std::isfinite(residual)) continue;
    int axis = 0;
    (cam_from_lidar.rotation * observation.normal_in_lidar).cwiseAbs().maxCoeff(&axis);
    ++facing[axis].num_observations;
    sum[axis] += residual;
    squares[axis] += residual * residual;
  }
  for (int axis = 0; axis < 3; ++axis) {
    const double n = static_cast<double>(facing[axis].num_observations);
    if (n == 0) continue;
    facing[axis].mean_residual_m = sum[axis] / n;
    facing[axis].rms_residual_m = std::sqrt(squares[axis] / n);
  }
  return facing;
}

}  // namespace colmap_lidar
