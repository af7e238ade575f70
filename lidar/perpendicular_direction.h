// The unit direction most nearly perpendicular to a set of unit vectors, near a guess. Two uses, one
// estimator: the vertical in a LiDAR frame is perpendicular to the normals of walls, and the vertical
// in a camera frame is perpendicular to the interpretation planes of vertical image lines (the plane
// through the camera centre and a segment contains the segment's 3D direction). Not part of Zhen et
// al. 2019: it measures cam_from_lidar's tilt about the two horizontal axes where motion cannot
// (bridge/initialization/vertical_alignment.h).
#pragma once

#include <Eigen/Core>

#include <vector>

namespace colmap_lidar {

struct PerpendicularDirectionOptions {
  // a vector takes part in the first iteration when within this angle of perpendicular [deg]
  double initial_max_angle_deg = 10;
  // ... and in the last one within this angle, or 3 robust sigmas (1.4826 median) of the previous
  // iteration's inliers when wider; the gate shrinks geometrically in between [deg]
  double final_max_angle_deg = 1;
  int num_iterations = 6;
  // fewer inliers: no direction
  size_t min_num_inliers = 10;

  bool Check() const;
};

// [rad^2] of a tilt direction that the vectors do not determine
inline constexpr double kUnknownTiltVariance = 1.0;

struct PerpendicularDirection {
  bool valid = false;
  // unit, on the side of the guess
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  // orthonormal columns perpendicular to `direction`: the tilt (a, b) moves it by a t1 + b t2
  Eigen::Matrix<double, 3, 2> tangent = Eigen::Matrix<double, 3, 2>::Zero();
  // of the tilt [rad^2]: residual variance times the inverse weighted normal matrix, independent
  // residuals assumed (so a lower bound when the vectors share errors)
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  size_t num_inliers = 0;
  // weighted RMS of the inliers' angle from perpendicular [deg]
  double rms_deg = 0;
};

// Minimises sum_i w_i (v_i . d)^2 over unit d by Gauss-Newton on its tilt from the guess, with the
// inlier gate shrinking per iteration. `weights` empty: all 1. A tilt direction without information
// (walls of one street all face across it: nothing says how the vertical leans along the street) keeps
// the guess and gets the variance kUnknownTiltVariance; not valid when neither direction has any.
PerpendicularDirection FitPerpendicularDirection(const std::vector<Eigen::Vector3d>& unit_vectors,
                                                 const std::vector<double>& weights,
                                                 const Eigen::Vector3d& guess,
                                                 const PerpendicularDirectionOptions& options);

// Orthonormal columns perpendicular to the unit `direction`.
Eigen::Matrix<double, 3, 2> TangentBasis(const Eigen::Vector3d& direction);

}  // namespace colmap_lidar
