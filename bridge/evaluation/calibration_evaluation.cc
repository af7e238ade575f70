#include "bridge/evaluation/calibration_evaluation.h"

#include "colmap_ext/logging.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace colmap_lidar {

double RotationErrorDeg(const colmap::Rigid3d& a, const colmap::Rigid3d& b) {
  return a.rotation.angularDistance(b.rotation) * 180.0 / M_PI;
}

std::string StationOfImageName(const std::string& image_name) {
  return std::filesystem::path(image_name).stem().string();
}

namespace {

// The spread of `centers` about their centroid (RMS distance), 1 if they coincide.
double CenterSpread(const Eigen::Matrix3Xd& centers) {
  const double spread =
      std::sqrt((centers.colwise() - centers.rowwise().mean()).colwise().squaredNorm().mean());
  return spread > 0 ? spread : 1;
}

// The registered cameras of the stations with a true pose, matched by station name.
struct MatchedCameras {
  std::vector<std::string> names;
  std::vector<const colmap::Image*> images;
  Eigen::Matrix3Xd estimated_centers, true_centers;
  std::vector<Eigen::Matrix3d> estimated_world_from_cam, true_world_from_cam;
};

MatchedCameras MatchCameras(const std::map<std::string, colmap::Rigid3d>& true_cam_from_world,
                            const colmap::Reconstruction& reconstruction,
                            std::vector<std::string>* missing_stations) {
  std::map<std::string, const colmap::Image*> by_station;
  for (const colmap::image_t image_id : reconstruction.RegImageIds()) {
    const colmap::Image& image = reconstruction.Image(image_id);
    by_station[StationOfImageName(image.Name())] = &image;
  }
  MatchedCameras matched;
  for (const auto& [name, pose] : true_cam_from_world) {
    const auto it = by_station.find(name);
    if (it == by_station.end()) {
      missing_stations->push_back(name);
    } else {
      matched.names.push_back(name);
      matched.images.push_back(it->second);
    }
  }
  const size_t n = matched.names.size();
  matched.estimated_centers.resize(3, n);
  matched.true_centers.resize(3, n);
  for (size_t i = 0; i < n; ++i) {
    matched.estimated_centers.col(i) = matched.images[i]->ProjectionCenter();
    matched.estimated_world_from_cam.push_back(
        matched.images[i]->CamFromWorld().rotation.toRotationMatrix().transpose());
    const colmap::Rigid3d& cam_from_world = true_cam_from_world.at(matched.names[i]);
    matched.true_centers.col(i) = colmap::Inverse(cam_from_world).translation;
    matched.true_world_from_cam.push_back(cam_from_world.rotation.toRotationMatrix().transpose());
  }
  return matched;
}

// true_world_from_model_world by Umeyama on each camera's centre and the tips of its three axes at
// the centres' spread: the centres alone leave the rotation about their line free when they are
// collinear (a straight drive), the axes fix it.
Eigen::Matrix4d AlignCameraFrames(const MatchedCameras& cameras, bool similarity) {
  const double true_lever = CenterSpread(cameras.true_centers);
  const double estimated_lever = similarity ? CenterSpread(cameras.estimated_centers) : true_lever;
  const Eigen::Index n = cameras.estimated_centers.cols();
  Eigen::Matrix3Xd estimated(3, 4 * n), truth(3, 4 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    estimated.col(4 * i) = cameras.estimated_centers.col(i);
    truth.col(4 * i) = cameras.true_centers.col(i);
    for (int axis = 0; axis < 3; ++axis) {
      estimated.col(4 * i + 1 + axis) =
          cameras.estimated_centers.col(i) +
          estimated_lever * cameras.estimated_world_from_cam[i].col(axis);
      truth.col(4 * i + 1 + axis) =
          cameras.true_centers.col(i) + true_lever * cameras.true_world_from_cam[i].col(axis);
    }
  }
  return Eigen::umeyama(estimated, truth, similarity);
}

// Each station's rotation and position error after the alignment `result->truth_from_model`
// (scaled by `result->alignment_scale`), and their means and maxima.
void AddStationErrors(const MatchedCameras& cameras,
                      const std::map<std::string, colmap::Rigid3d>& true_cam_from_world,
                      CalibrationEvaluation* result) {
  const Eigen::Matrix3d rotation = result->truth_from_model.rotation.toRotationMatrix();
  const Eigen::Vector3d translation = result->truth_from_model.translation;
  double sum_rotation = 0, sum_position = 0;
  for (size_t i = 0; i < cameras.names.size(); ++i) {
    const std::string& name = cameras.names[i];
    const Eigen::Vector3d center =
        result->alignment_scale * rotation * cameras.estimated_centers.col(i) + translation;
    const double position_error_mm = 1000 * (center - cameras.true_centers.col(i)).norm();
    // cam_from_true_world = cam_from_model_world * model_world_from_true_world (rotation part).
    const Eigen::Quaterniond cam_from_true_world =
        cameras.images[i]->CamFromWorld().rotation * Eigen::Quaterniond(rotation.transpose());
    const double rotation_error_deg =
        cam_from_true_world.angularDistance(true_cam_from_world.at(name).rotation) * 180 / M_PI;
    result->rotation_error_deg[name] = rotation_error_deg;
    result->position_error_mm[name] = position_error_mm;
    sum_rotation += rotation_error_deg;
    sum_position += position_error_mm;
    result->max_rotation_error_deg = std::max(result->max_rotation_error_deg, rotation_error_deg);
    result->max_position_error_mm = std::max(result->max_position_error_mm, position_error_mm);
  }
  result->mean_rotation_error_deg = sum_rotation / cameras.names.size();
  result->mean_position_error_mm = sum_position / cameras.names.size();
}

}  // namespace

CalibrationEvaluation EvaluateCalibration(
    const colmap::Rigid3d& true_cam_from_lidar,
    const colmap::Rigid3d& estimated_cam_from_lidar,
    const std::map<std::string, colmap::Rigid3d>& true_cam_from_world,
    const colmap::Reconstruction& reconstruction,
    TrajectoryAlignment pose_alignment) {
  CalibrationEvaluation result;
  result.cam_from_lidar_rotation_error_deg =
      RotationErrorDeg(true_cam_from_lidar, estimated_cam_from_lidar);
  result.cam_from_lidar_translation_error_in_cam_mm =
      1000 * (estimated_cam_from_lidar.translation - true_cam_from_lidar.translation);
  result.cam_from_lidar_translation_error_mm =
      result.cam_from_lidar_translation_error_in_cam_mm.norm();

  if (true_cam_from_world.empty()) {
    return result;  // no true poses (a KITTI drive): the extrinsic only
  }
  const MatchedCameras cameras =
      MatchCameras(true_cam_from_world, reconstruction, &result.missing_stations);
  result.num_stations_evaluated = cameras.names.size();
  THROW_CHECK_GE(cameras.names.size(), 3) << "Fewer than 3 stations of the ground "
                                             "truth are registered in the model";
  const Eigen::Matrix4d alignment =
      AlignCameraFrames(cameras, pose_alignment == TrajectoryAlignment::kSimilarity);
  result.alignment = pose_alignment;
  const Eigen::Matrix3d scaled_rotation = alignment.topLeftCorner<3, 3>();
  result.alignment_scale = std::cbrt(scaled_rotation.determinant());
  result.truth_from_model =
      colmap::Rigid3d(Eigen::Quaterniond(scaled_rotation / result.alignment_scale),
                      alignment.topRightCorner<3, 1>());
  AddStationErrors(cameras, true_cam_from_world, &result);
  return result;
}

}  // namespace colmap_lidar
