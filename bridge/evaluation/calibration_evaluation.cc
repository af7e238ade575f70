#include "bridge/evaluation/calibration_evaluation.h"

#include "colmap_ext/logging.h"

#include <Eigen/Geometry>

#include <filesystem>

namespace colmap_lidar {

double RotationErrorDeg(const colmap::Rigid3d& a, const colmap::Rigid3d& b) {
  return a.rotation.angularDistance(b.rotation) * 180.0 / M_PI;
}

std::string StationOfImageName(const std::string& image_name) {
  return std::filesystem::path(image_name).stem().string();
}

CalibrationEvaluation EvaluateCalibration(
    const colmap::Rigid3d& true_cam_from_lidar,
    const colmap::Rigid3d& estimated_cam_from_lidar,
    const std::map<std::string, colmap::Rigid3d>& true_cam_from_world,
    const colmap::Reconstruction& reconstruction,
    bool similarity_alignment) {
  CalibrationEvaluation result;
  result.cam_from_lidar_rotation_error_deg =
      RotationErrorDeg(true_cam_from_lidar, estimated_cam_from_lidar);
  result.cam_from_lidar_translation_error_in_cam_mm =
      1000 * (estimated_cam_from_lidar.translation - true_cam_from_lidar.translation);
  result.cam_from_lidar_translation_error_mm =
      result.cam_from_lidar_translation_error_in_cam_mm.norm();

  if (true_cam_from_world.empty()) {
    result.alignment = "none";  // no true poses (a KITTI drive): the extrinsic only
    return result;
  }
  std::vector<std::string> names;
  std::vector<const colmap::Image*> images;
  std::map<std::string, const colmap::Image*> by_station;
  for (const colmap::image_t image_id : reconstruction.RegImageIds()) {
    const colmap::Image& image = reconstruction.Image(image_id);
    by_station[StationOfImageName(image.Name())] = &image;
  }
  for (const auto& [name, pose] : true_cam_from_world) {
    const auto it = by_station.find(name);
    if (it == by_station.end()) {
      result.missing_stations.push_back(name);
    } else {
      names.push_back(name);
      images.push_back(it->second);
    }
  }
  result.num_stations_evaluated = names.size();
  THROW_CHECK_GE(names.size(), 3) << "Fewer than 3 stations of the ground "
                                     "truth are registered in the model";
  Eigen::Matrix3Xd estimated_centers(3, names.size()), true_centers(3, names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    estimated_centers.col(i) = images[i]->ProjectionCenter();
    true_centers.col(i) = colmap::Inverse(true_cam_from_world.at(names[i])).translation;
  }
  // true_world_from_model_world, by Umeyama on the camera centres.
  const Eigen::Matrix4d alignment =
      Eigen::umeyama(estimated_centers, true_centers, similarity_alignment);
  result.alignment = similarity_alignment ? "similarity" : "rigid";
  const Eigen::Matrix3d scaled_rotation = alignment.topLeftCorner<3, 3>();
  result.alignment_scale = std::cbrt(scaled_rotation.determinant());
  const Eigen::Matrix3d rotation = scaled_rotation / result.alignment_scale;
  const Eigen::Vector3d translation = alignment.topRightCorner<3, 1>();
  result.truth_from_model = colmap::Rigid3d(Eigen::Quaterniond(rotation), translation);

  double sum_rotation = 0, sum_position = 0;
  for (size_t i = 0; i < names.size(); ++i) {
    const Eigen::Vector3d center =
        result.alignment_scale * rotation * estimated_centers.col(i) + translation;
    const double position_error_mm = 1000 * (center - true_centers.col(i)).norm();
    // cam_from_true_world = cam_from_model_world * model_world_from_true_world (rotation part).
    const Eigen::Quaterniond cam_from_true_world =
        images[i]->CamFromWorld().rotation * Eigen::Quaterniond(rotation.transpose());
    const double rotation_error_deg =
        cam_from_true_world.angularDistance(true_cam_from_world.at(names[i]).rotation) * 180 / M_PI;
    result.rotation_error_deg[names[i]] = rotation_error_deg;
    result.position_error_mm[names[i]] = position_error_mm;
    sum_rotation += rotation_error_deg;
    sum_position += position_error_mm;
    result.max_rotation_error_deg = std::max(result.max_rotation_error_deg, rotation_error_deg);
    result.max_position_error_mm = std::max(result.max_position_error_mm, position_error_mm);
  }
  result.mean_rotation_error_deg = sum_rotation / names.size();
  result.mean_position_error_mm = sum_position / names.size();
  return result;
}

}  // namespace colmap_lidar
