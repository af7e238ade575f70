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
  // Similarity variant: a motion whose rotation axis, or translation direction, contradicts the fit
  // by more is left out, worst first, and the fit repeated (a wrong two-view geometry along a drive
  // otherwise spoils the whole fit); the fit fails when more than half would go.
  double max_motion_residual_deg = 10.0;

  bool Check() const;
};

struct HandEyeResult {
  // Rotation and translation recovered (for the similarity variant: scale too).
  bool unique = false;
  // Similarity variant: the rotation is recovered, but the translation along
  // `unobservable_axis_in_cam` is not (motion about one axis only, e.g. a car on a plane).
  bool rotation_unique = false;
  Eigen::Vector3d unobservable_axis_in_cam = Eigen::Vector3d::Zero();
  // Metres per unit of the camera motions (similarity variant; 1 otherwise).
  double scale = 1;
  std::string message;  // why not unique, or a summary
  colmap::Rigid3d cam_from_lidar;
  int num_motions = 0;        // used
  int num_contradicting = 0;  // similarity variant: left out as contradicting the fit
  // Similarity variant: one of those left out only because its axis kept a general fit above
  // max_axis_residual_deg rms.
  bool axis_misfit_left_out = false;
  double max_axis_angle_deg = 0;  // spread of the rotation axes
  double rotation_rms_deg = 0;    // residual of the axis fit
  double translation_rms_m = 0;   // residual of the linear system
};

HandEyeResult SolveHandEye(const std::vector<HandEyeMotion>& motions,
                           const HandEyeOptions& options);

// The similarity variant for camera motions known up to scale (a monocular model): A_k = (R_A, a_k)
// with metric translation s a_k, so (R_A - I) t_X + s a_k = R_X t_B, linear in (t_X, s). When all
// rotation axes are parallel (planar driving), the rotation also uses the translation directions of the
// motions that hardly rotate (a_k / |a_k| = R_X t_B / |t_B|), and the component of t_X along the common
// axis, which no motion observes, is taken from `axis_translation_fallback` (e.g. the guess) and named
// in the result.
// `per_motion_scale`: each camera translation has a scale of its own (unit directions from two-view
// geometry): (R_A - I) t_X + s_k a_k = R_X t_B with one s_k per motion; `scale` is then their mean.
// Planar motion with per-motion scales takes all of t_X from the fallback (the forward translation is
// confounded with the scales when the platform drives mostly straight).
HandEyeResult SolveSimilarityHandEye(const std::vector<HandEyeMotion>& motions,
                                     const HandEyeOptions& options,
                                     const Eigen::Vector3d& axis_translation_fallback,
                                     bool per_motion_scale = false);

// Least-squares scale s of up-to-scale camera motions given cam_from_lidar: s a_k = R_X t_B - (R_A - I) t_X.
// Throws if no motion translates.
double HandEyeScale(const std::vector<HandEyeMotion>& motions,
                    const colmap::Rigid3d& cam_from_lidar);

}  // namespace colmap_lidar
