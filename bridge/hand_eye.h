// Hand-eye calibration of cam_from_lidar from paired relative motions (the uniqueness conditions of Zhen et al. 2019):
//
//   A_k X = X B_k,  A_k = cam_i_from_cam_j (images), B_k = lidar_i_from_lidar_j (LiDAR), X = cam_from_lidar.
//
// Rotation: the rotation axis of A_k is R_X times the axis of B_k; R_X is the rotation that best maps the
// B axes onto the A axes (Kabsch, weighted by the rotation angle). Translation: (R_A - I) t_X =
// R_X t_B - t_A stacked over all pairs, linear least squares. Unique only with >= 2 motions whose
// rotation axes are not parallel; otherwise the result says why and is not to be used.
#pragma once

#include "colmap/geometry/rigid3.h"

#include <string>
#include <vector>

namespace colmap_lidar {

struct HandEyeMotion {
  colmap::Rigid3d cam_i_from_cam_j;
  colmap::Rigid3d lidar_i_from_lidar_j;
};

struct HandEyeOptions {
  // motions rotating less carry no axis
  double min_rotation_deg = 5.0;
  // two axes closer than this count as parallel
  double min_axis_angle_deg = 10.0;
  // consistency of A and B rotation angles
  double max_axis_residual_deg = 2.0;

  bool Check() const;
};

struct HandEyeResult {
  bool unique = false;
  std::string message;  // why not unique, or a summary
  colmap::Rigid3d cam_from_lidar;
  int num_motions = 0;            // used
  double max_axis_angle_deg = 0;  // spread of the rotation axes
  double rotation_rms_deg = 0;    // residual of the axis fit
  double translation_rms_m = 0;   // residual of the linear system
};

HandEyeResult SolveHandEye(const std::vector<HandEyeMotion>& motions,
                           const HandEyeOptions& options);

}  // namespace colmap_lidar
