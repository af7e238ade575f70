// Accuracy of an estimated cam_from_lidar and of a sparse model's station poses against ground truth.
//
// Pose errors are measured after aligning the estimated cameras to the true ones by a rigid
// transform (rotation + translation, no scale: the model is metric) or, on request, a similarity
// (for models of unknown scale), fitted to each camera's centre and the tips of its axes (the
// centres alone leave the rotation about their line free on a straight drive). Station i is matched by name: the stem of the image name.
#pragma once

#include "lidar/trajectory_error.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/reconstruction.h"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace colmap_lidar {

struct CalibrationEvaluation {
  double cam_from_lidar_rotation_error_deg = 0;
  double cam_from_lidar_translation_error_mm = 0;
  Eigen::Vector3d cam_from_lidar_translation_error_in_cam_mm = Eigen::Vector3d::Zero();
  // How the model's stations were aligned with the true ones; none without true poses.
  std::optional<TrajectoryAlignment> alignment;
  double alignment_scale = 1;
  // The alignment's rotation and translation: true_world_from_model_world without the scale (the
  // transform evaluate_model applies to a dense model of this sparse model).
  colmap::Rigid3d truth_from_model;
  size_t num_stations_evaluated = 0;
  std::vector<std::string> missing_stations;         // in the truth, not registered in the model
  std::map<std::string, double> rotation_error_deg;  // per station
  std::map<std::string, double> position_error_mm;   // per station
  double mean_rotation_error_deg = 0, max_rotation_error_deg = 0;
  double mean_position_error_mm = 0, max_position_error_mm = 0;
};

// Rotation angle between two rotations and distance between translations of two transforms.
double RotationErrorDeg(const colmap::Rigid3d& a, const colmap::Rigid3d& b);

// With no true poses (`true_cam_from_world` empty, e.g. a KITTI drive), only the extrinsic is
// evaluated: no alignment, no station errors.
CalibrationEvaluation EvaluateCalibration(
    const colmap::Rigid3d& true_cam_from_lidar,
    const colmap::Rigid3d& estimated_cam_from_lidar,
    const std::map<std::string, colmap::Rigid3d>& true_cam_from_world,
    const colmap::Reconstruction& reconstruction,
    TrajectoryAlignment alignment);

// "left/000.png" -> "000"
std::string StationOfImageName(const std::string& image_name);

}  // namespace colmap_lidar
