// Observability of the camera-LiDAR extrinsic T_e = cam_from_lidar after the joint solve:
// - its 6x6 covariance from the joint problem's Gauss-Newton information H = J^T J (every other variable
//   block marginalised). Two estimates: the formal one, H^-1 scaled by the a-posteriori variance factor,
//   assumes independent residuals; the reported one is cluster-robust (a sandwich H^-1 (sum_c g_c g_c^T)
//   H^-1 with g_c = J_c^T r_c summed per cluster), clustered two ways (Cameron, Gelbach & Miller
//   2011): by landmark, whose residuals share its texture's and its surface's errors, and by one
//   sensor's capture at one station (an image's reprojections, its depth priors, the LiDAR pairs
//   of one target sweep), whose residuals share that capture's errors; the formal covariance is
//   then several times too optimistic. Directions whose
//   standard deviation exceeds a threshold are named in words;
// - the uniqueness test of Zhen et al. 2019 on the relative motions: T_e is unique only with >= 3 stations whose
//   relative rotation axes are not all parallel (hand-eye calibration, AX = XB).
// Units: rotation as a rotation vector about the camera axes in degrees (twice Ceres'
// EigenQuaternionManifold tangent, which is left-multiplied and rotates by 2|delta|), translation in
// millimetres along the camera axes.
#pragma once

#include "bridge/joint/term_pulls.h"

#include "colmap/scene/reconstruction.h"

#include <Eigen/Core>
#include <ceres/problem.h>

#include <array>
#include <string>
#include <unordered_map>
#include <vector>

namespace colmap_lidar {

struct ObservabilityOptions {
  // A direction of T_e whose standard deviation exceeds these is called unobservable.
  double unobservable_translation_mm = 5.0;
  double unobservable_rotation_deg = 0.2;
  // Systematic relative scale error of the stereo depth (baseline/focal calibration, sub-pixel bias),
  // a "consider" parameter: its effect on T_e, sigma^2 * s s^T with s = dT_e/dscale, is added to the
  // covariance (random residual scatter cannot reveal an error common to every depth prior).
  double stereo_scale_sigma = 0.001;
  // Systematic disparity error of the stereo depth over the left image [px]: an offset and slopes
  // per unit of normalised image x and y (a rectified pair's residual relative yaw or principal
  // point offset, focal mismatch, relative roll; the matcher's sub-pixel bias). Consider
  // parameters like the scale, each with this sigma (colmap_ext/depth_prior_cost.h's field c times
  // b f). The scale and the field are the stereo depth's errors common to every prior, which the
  // priors' scatter cannot reveal.
  double disparity_bias_sigma_px = 0.02;
  // How residuals are grouped for the cluster-robust covariance: by landmark and by one sensor's
  // capture at one station (a real capture), or by landmark only (a simulated capture whose noise
  // is independent between stations by construction, as the survey planner's: there the station
  // sums of one draw of a few stations would only add that draw's sampling noise).
  enum class ClusterGrouping { kLandmarkAndCapture, kLandmark };
  ClusterGrouping cluster_grouping = ClusterGrouping::kLandmarkAndCapture;
  // relative rotations below this do not count as rotating
  double min_rotation_deg = 2.0;
  // axes closer than this are parallel
  double max_parallel_axes_deg = 5.0;

  bool Check() const;
};

struct ExtrinsicUncertainty {
  bool computed = false;
  std::string message;  // why not, if not computed
  // 6x6 covariance of (rotation vector [deg] about the camera axes, translation [mm]) of cam_from_lidar:
  // cluster-robust if it could be computed (see cluster_robust), else the formal one.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> formal_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool cluster_robust = false;
  // Rotation [deg] and translation [mm] of T_e per unit of relative stereo scale error (the consider
  // parameter); its contribution stereo_scale_sigma^2 s s^T is included in `covariance`.
  Eigen::Matrix<double, 6, 1> stereo_scale_sensitivity = Eigen::Matrix<double, 6, 1>::Zero();
  // The same per pixel of the disparity bias field's offset, x slope and y slope (columns); its
  // contribution disparity_bias_sigma_px^2 S S^T is included in `covariance`.
  Eigen::Matrix<double, 6, 3> disparity_bias_sensitivity = Eigen::Matrix<double, 6, 3>::Zero();
  int num_clusters = 0;
  double variance_factor = 1;  // 2 cost / (residuals - parameters)
  Eigen::Matrix<double, 6, 1> eigenvalues =
      Eigen::Matrix<double, 6, 1>::Zero();  // std devs, ascending
  Eigen::Matrix<double, 6, 6> eigenvectors = Eigen::Matrix<double, 6, 6>::Zero();  // columns
  std::vector<std::string> unobservable;  // one sentence per unobservable direction
  // Axes (rx ry rz tx ty tz about/along the camera axes) that lie mostly in directions held at
  // their start: they have no sigma (the covariance is zero in the held directions).
  std::array<bool, 6> undetermined = {false, false, false, false, false, false};
  // Each data term's pull on cam_from_lidar (empty without the cluster-robust covariance), and one
  // sentence per axis on which two terms pull apart (bridge/joint/term_pulls.h).
  std::vector<TermPull> term_pulls;
  std::vector<std::string> term_disagreements;
};

struct MotionAnalysis {
  int num_stations = 0;
  int num_rotating_pairs = 0;     // relative rotation above 2 deg
  double max_axis_angle_deg = 0;  // largest angle between two relative rotation axes
  // largest relative rotation about an axis perpendicular to the main rotation axis
  double second_axis_rotation_deg = 0;
  Eigen::Vector3d common_axis_in_cam = Eigen::Vector3d::Zero();  // if all axes are parallel
  // Unit direction of travel between the stations in each camera's own frame (the principal direction
  // of the camera centres seen from each other, sign free); zero if the stations do not move.
  Eigen::Vector3d travel_direction_in_cam = Eigen::Vector3d::Zero();
  // The test of Zhen et al. 2019: >= 3 stations, axes not all parallel (more than
  // max_parallel_axes_deg apart, and some pair turning min_rotation_deg about a second axis).
  bool unique = false;
  std::string verdict;
};

// The largest angle [deg] between two of the lines along `unit_axes` (0 to 90; 0 for fewer than
// two): the same value as comparing every pair, found without most pairs when the axes gather
// about one direction (the angle between lines is a metric, so two axes at angles a and b from
// their main direction are at most a + b apart).
double LargestAngleBetweenAxesDeg(const std::vector<Eigen::Vector3d>& unit_axes);

// The uniqueness test of Zhen et al. 2019 on the relative motions of the registered cameras.
MotionAnalysis AnalyseMotion(const colmap::Reconstruction& reconstruction,
                             const ObservabilityOptions& options);

// Empty if the reported covariance of T_e has been validated by coverage for this kind of capture
// (stations that rotate about two axes: tests/joint_adjuster_coverage_test.cc and the T specimen end
// to end), else one sentence saying why it has not. A moving platform (sweeps, or a one-axis
// hand-eye) whose stations turn about one axis, or not at all, is not: on the simulated drives errors
// with a sign common to the runs exceed the reported sigmas (the height; where the drive does not
// turn, the pitch, which follows the cameras' direction of travel), see
// docs/benchmarks/uncertainty_drives.md and docs/benchmarks/travel_direction.md.
std::string UncertaintyCaveat(const MotionAnalysis& motion, bool moving_platform);

// What the covariance of T_e is computed from: the joint problem and T_e's blocks in it (both
// variable parameter blocks; the rotation with a quaternion manifold of tangent size 3, the
// translation possibly with a subset manifold), and its residual blocks by role.
struct ExtrinsicUncertaintyInputs {
  ceres::Problem* problem = nullptr;
  double* cam_from_lidar_rotation = nullptr;
  double* cam_from_lidar_translation = nullptr;
  // Projections (sums of d d^T over orthonormal camera-frame directions d) onto the directions of
  // T_e's rotation and translation held at their start: the blocks' manifolds are subspace
  // manifolds without them (bridge/joint/subspace_manifold.h), so they get no variance.
  Eigen::Matrix3d held_rotation = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d held_translation = Eigen::Matrix3d::Zero();
  // Of those, the ones held because the data do not determine them (the rest are held by the
  // user): named in `unobservable`, and the axes lying mostly in them marked undetermined.
  Eigen::Matrix3d undetermined_rotation = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d undetermined_translation = Eigen::Matrix3d::Zero();
  // Every data residual block of the problem, grouped (see above).
  std::vector<std::vector<ceres::ResidualBlockId>> clusters;
  // Empty (one-way clustering), or per cluster two group keys for two-way clustering: its landmark
  // and its station-and-sensor (-1: the cluster is a group of its own in that grouping).
  std::vector<std::array<int, 2>> cluster_groups;
  // Per cluster, its data term (an index into term_names); empty: no term pulls.
  std::vector<int> cluster_term;
  std::vector<std::string> term_names;
  // Residual blocks that are not data (the weak extrinsic prior): they keep the information
  // invertible for the sandwich but never decide what is observable.
  std::vector<ceres::ResidualBlockId> regularizers;
  // Whitened residual blocks of measurements with a known covariance (the stereo-LiDAR alignment's
  // E_x): data, whose share of the sandwich is their information J^T J, not a score (one draw of a
  // measurement says nothing about its spread).
  std::vector<ceres::ResidualBlockId> measurements;
  // Data residuals that compressed blocks stand for beyond their own rows (for the variance
  // factor's redundancy).
  size_t hidden_residuals = 0;
  // Per depth-prior block, d(residual)/d(the stereo depth's consider parameters): the relative
  // scale (-d / sigma_d) and the disparity bias field's offset, x and y slope [px]
  // (d^2 (1, x, y) / (b f sigma_d)).
  std::unordered_map<ceres::ResidualBlockId, Eigen::Vector4d> depth_consider_derivative;
};

// Marginal covariance of T_e in `inputs.problem`; `motion` turns unobservable directions into
// advice.
ExtrinsicUncertainty ComputeExtrinsicUncertainty(const ExtrinsicUncertaintyInputs& inputs,
                                                 const MotionAnalysis& motion,
                                                 const ObservabilityOptions& options);

}  // namespace colmap_lidar
