// The back end of Zhen et al. 2019: ONE Levenberg-Marquardt problem over camera poses T, landmarks L and the
// camera-LiDAR extrinsic T_e, with cost 1/2 sum w_c (E_f^2 + E_d^2) + 1/2 sum w_l E_l^2, built inside
// COLMAP 3.10's own Ceres problem.
//
// Conventions
// - COLMAP image i = station i's left camera; its pose is cam_from_world_i (COLMAP's parameter blocks:
//   Rigid3d::rotation.coeffs() as an Eigen quaternion, xyzw in memory, and Rigid3d::translation).
// - T_e = cam_from_lidar: one shared parameter block pair (quaternion manifold through COLMAP's
//   SetQuaternionManifold, plus translation). Files we write store quaternions w first (qw qx qy qz).
// - world_from_lidar_i = inverse(cam_from_world_i) * cam_from_lidar.
// - A LiDAR observation (target i, source j, p in lidar_j, q and n in lidar_i):
//   E_l = n^T (lidar_i_from_lidar_j p - q) / sigma_l,
//   lidar_i_from_lidar_j = inverse(T_e) cam_from_world_i inverse(cam_from_world_j) T_e
//   (bridge/joint/lidar_point_to_plane_cost.h).
// - Optional (not in the paper; on by default for a monocular rig): the landmark-to-LiDAR-plane
//   residual E_m = n^T (lidar_i_from_world X - q) / sigma_m with w_m
// (bridge/joint/landmark_lidar_plane_cost.h).
// - Optional (not in the paper): a measurement of T_e made outside the problem (the pose initialiser's
//   stereo-LiDAR alignment), E_x = W [rotvec(R_e R_x^-1); t_e - t_x] with W^T W its inverse covariance
//   (bridge/joint/extrinsic_deviation_cost.h; JointProblemData::extrinsic_measurements), and
// rig.json's   guess when it carries a sigma (a prior).
// - E_f = COLMAP's reprojection residual in pixels (sigma_p = 1 px); E_d = the depth-prior residual
//   (colmap_ext/depth_prior_cost.h), z-depth with sigma_d = d^2/(b f) sigma_p.
// - Gauge: the first station's (smallest image_id's) pose is constant. Metric scale comes from the depth
//   priors and the LiDAR; nothing else is fixed.
//
// Injection (COLMAP 3.10): BundleAdjuster::SetUpProblem() -> Problem() -> add our residual blocks ->
// SetUpSolverOptions() -> ceres::Solve. BundleAdjuster::Solve() is never called (it would rebuild the
// problem). COLMAP's problem does not own loss functions; this class owns every loss it passes.
#pragma once

#include "bridge/joint/extrinsic_observability.h"
#include "bridge/joint/landmark_lidar_term.h"
#include "bridge/joint/variance_components.h"
#include "colmap_ext/extension_database.h"
#include "lidar/point_to_plane_association.h"
#include "lidar/robust_loss.h"
#include "lidar/station_cloud.h"
#include "lidar/util/named_choice.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/reconstruction.h"

#include <ceres/solver.h>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace colmap_lidar {

// The three modes compared by Zhen et al. 2019.
enum class JointMode {
  kJoint,          // T_e refined with everything else
  kPrecalibrated,  // T_e held constant
  kStereoOnly,     // no LiDAR term (weight 0), T_e constant
};
inline constexpr NamedChoices<JointMode, 3> kJointModeNames = {
    {{"joint", JointMode::kJoint},
     {"precalibrated", JointMode::kPrecalibrated},
     {"stereo_only", JointMode::kStereoOnly}}};

struct JointAdjusterOptions {
  JointMode mode = JointMode::kJoint;
  // Standard deviation of a LiDAR point-to-plane distance (the paper uses 0.02 - 0.1 m). sigma_p = 1 px
  // is COLMAP's reprojection weight; sigma_d comes with each depth prior. The joint_adjuster command
  // sets it to the rig's LiDAR range noise (rig.json lidar.range_noise_m, StationRig::LidarRangeNoiseM).
  double sigma_lidar_m = 0.02;
  // Estimate each data group's variance factor (reprojection, depth priors, E_l, E_m) with the solve
  // (bridge/joint/variance_components.h) and weight the group by it: the nominal sigmas (1 px,
  // sigma_d, sigma_lidar_m, sigma_landmark_lidar_m) and weights below are then only the start.
  bool estimate_variance_components = true;
  // w_c of E_d (E_f keeps weight 1).
  double depth_weight = 1.0;
  // With LiDAR terms, E_d joins from this round on (1: from the start, as in the paper). The start's
  // landmarks are triangulated through the initial cam_from_lidar: from a guess degrees off their
  // depths are tens of sigma_d off the priors, and a first solve with E_d deforms the model. A first
  // round without E_d (reprojection, LiDAR, E_m) fits them first.
  int first_depth_prior_round = 2;
  // w_l of E_l.
  double lidar_weight = 1.0;
  // E_l leaves T_e's rotation about the driving direction to the other terms (an angle of its own,
  // bridge/joint/free_axis_extrinsic_cost.h): on a moving platform that turns about one axis, E_l
  // knows that rotation only from how the turns' axis maps between camera and LiDAR, which a drift of 0.001 deg
  // per frame moves by tenths of a degree. The axis is the direction of travel in the camera frame,
  // perpendicular to the common turn axis.
  bool free_lidar_drive_roll = false;
  // w_m of E_m, the landmark-to-LiDAR-plane term; 0 = off (the paper's cost). The pipeline turns it on
  // for a monocular rig, where it gives the landmarks their metric depth.
  double landmark_lidar_weight = 0.0;
  // A moving platform: E_m carries the offset dt of the LiDAR's clock from the cameras' as a
  // parameter (bridge/joint/landmark_lidar_plane_cost.h, TimedLandmarkLidarPlaneCostFunctor), with
  // each station's camera velocity from its neighbours (JointProblemData::image_times). Where the velocity
  // in the camera frame does not change (a straight drive at constant speed), dt and T_e's translation
  // along the travel are one direction, which the covariance then reports as undetermined.
  bool estimate_time_offset = false;
  // Estimate the stereo depth's bias field (colmap_ext/depth_prior_cost.h) against E_m, which
  // measures depth without it; off: the field is held at zero. Estimated, it also absorbs whatever
  // else makes the cameras' depths disagree with the LiDAR's (sweeps not de-skewed, a clock
  // offset), so it is for rigs whose LiDAR side is clean.
  bool estimate_depth_bias = false;
  // Estimate E_m's oblique-view offset delta (bridge/joint/landmark_lidar_plane_cost.h): the
  // landmarks on surfaces seen at grazing angles sit off them, towards the camera
  // (docs/benchmarks/landmark_offsets.md); off: delta is held at zero. Estimated, it has a prior of
  // 1 px over the cameras' mean focal length and is marginalised in cam_from_lidar's covariance.
  bool estimate_oblique_offset = false;
  // sigma_m of E_m: the landmark's triangulation and the LiDAR surface together.
  double sigma_landmark_lidar_m = 0.02;
  // E_m outliers: beyond this distance or beyond max_landmark_plane_sigmas * sigma_m (absolute and in
  // sigma units), zero weight until none remain; re-associated each round with the LiDAR term's gate,
  // which is also the cap of every round but the last (a coarse start is pulled in first).
  double max_landmark_plane_m = 0.1;
  double max_landmark_plane_sigmas = 3.0;
  // Robust loss on every term (none in the paper). With a loss, each LiDAR observation is its own
  // residual block (the loss applies per observation); without, one block per directed station pair.
  RobustLoss loss = RobustLoss::kNone;
  // Each LiDAR pair block in its compressed form (bridge/joint/lidar_pair_cost.h): the same cost,
  // gradient and Gauss-Newton model in 13 moment rows, evaluated in O(1) instead of one row per observation.
  bool compress_lidar_blocks = true;
  // Scale of the loss in units of the whitened residual.
  double loss_scale = 1.0;
  // Outliers get zero weight until none remain (the paper's 3 px / 0.01 m / 0.1 m). A depth prior is an
  // outlier beyond `max_depth_error_sigmas` of its own sigma_d = d^2/(b f) sigma_p, and, if
  // `max_depth_error_m` > 0, beyond that absolute cap; it comes back when it fits again after a solve.
  double max_reprojection_error_px = 3.0;
  double max_depth_error_sigmas = 3.0;
  // Scale the sigma gate by the priors' robust residual scale s = 1.4826 median |error| / sigma_d,
  // clamped to [0.1, 1]: sigma_d with sigma_p = 1 px is several times conservative for SGBM, and a
  // gate of 3 sigma_d would then be many actual sigmas. With s = 1 this is 3 sigma_d.
  bool depth_gate_from_residual_scale = true;
  double max_depth_error_m = 0.0;
  double max_point_to_plane_m = 0.1;
  int max_outlier_iterations = 10;
  // ICP-like re-association of the LiDAR observations (the paper: 4 rounds).
  int num_association_rounds = 4;
  // Beyond the paper: further rounds (at the final gate, up to this many in all) while the last round
  // still moved T_e by more than round_convergence_deg or round_convergence_mm: a coarse start (the
  // hand-eye of a car, a degree and decimetres off) is still converging after 4 rounds.
  int max_association_rounds = 10;
  double round_convergence_deg = 0.01;
  double round_convergence_mm = 1.0;
  // num_samples per directed pair; max_distance is the final gate.
  AssociationOptions association;
  // Gate of round 0, halved per round down to association.max_distance.
  double initial_association_distance_m = 0.5;
  // Extrinsic degrees of freedom held constant in joint mode (users ask for it): rotation as a whole,
  // translation per camera axis.
  bool hold_rotation = false;
  std::array<bool, 3> hold_translation = {false, false, false};
  // Weak prior on T_e's translation at its initial value (bridge/joint/extrinsic_prior_cost.h):
  // keeps an unobservable direction where it started instead of letting it drift; 0 = off. It is left out of the
  // uncertainty, so an unobservable direction is named whatever this sigma.
  double extrinsic_prior_sigma_m = 1.0;
  // Never drift: when the solve finds directions of T_e unobservable (their standard deviation above
  // hold_rotation_deg / hold_translation_mm), the adjustment runs again from the initial state with
  // those directions held, at JointProblemData::cam_from_lidar_guess along them if there is one, else
  // at their initial value (T_e's manifolds without them, bridge/joint/subspace_manifold.h); the
  // report names them.
  bool hold_unobservable = true;
  // Above the reporting thresholds of `observability` (5 mm / 0.2 deg: "not calibrated to that"): a
  // direction the data know to 6 mm (a car's height from landmarks on the road, E_m) beats an initial
  // value off by decimetres (0 from the hand-eye, or a tape-measured guess); holding it there biases
  // the rotation too (0.2 m of height at 10 m range is 1.2 deg).
  double hold_rotation_deg = 0.5;
  double hold_translation_mm = 20.0;
  int max_num_iterations = 100;
  ObservabilityOptions observability;

  bool Check() const;
};

// A measurement of T_e made outside the joint problem (the pose initialiser's stereo-LiDAR alignment):
// cam_from_lidar and its 6x6 covariance, rotation [rad] about the camera axes (left of the rotation)
// then translation [m].
struct ExtrinsicMeasurement {
  colmap::Rigid3d cam_from_lidar;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Identity();
  std::string source;  // for reports, e.g. "stereo-LiDAR alignment"
  // Outside knowledge (rig.json's guess with its sigma), not a fit to the data of this problem: the
  // directions it determines are not held at their start.
  bool prior = false;
};

// What the joint problem needs besides COLMAP's reconstruction. Borrowed by JointAdjuster::Run for the
// duration of the call only.
struct JointProblemData {
  // Depth priors per image, keyed by point2D_idx.
  std::unordered_map<colmap::image_t, std::unordered_map<colmap::point2D_t, DepthPrior>>
      depth_priors;
  // Each station's cloud (lidar frame, normals, k-d tree), keyed by image_id; not owned.
  std::map<colmap::image_t, const StationCloud*> clouds;
  // The pose graph A_c v A_l as unordered image pairs; LiDAR observations are drawn in both directions.
  std::vector<std::pair<colmap::image_t, colmap::image_t>> pairs;
  // Capture time of each image [s] (empty: the images are frames in image_id order, one unit apart);
  // for the camera velocities of estimate_time_offset.
  std::map<colmap::image_t, double> image_times;
  // The stereo rig's baseline times its rectified focal length [m px] (0: no stereo rig): converts
  // the depth priors' disparity bias field between pixels and inverse depth.
  double stereo_baseline_focal = 0;
  // Each joins the cost as E_x (bridge/joint/extrinsic_deviation_cost.h) in joint mode.
  std::vector<ExtrinsicMeasurement> extrinsic_measurements;
  // rig.json's guess without a sigma: outside knowledge, though not a prior (empty: none). A
  // direction the data leave undetermined is held at the guess's value along it, not at the
  // start's: a start fitted to these data (the pose initialiser's) knows nothing along it either.
  std::optional<colmap::Rigid3d> cam_from_lidar_guess;

  bool HasExtrinsicPrior() const;
};

struct TermStats {
  // Residuals in the problem of this solve.
  size_t num_observations = 0;
  // Given weight zero so far (in force after this solve).
  size_t num_outliers = 0;
  // 1/2 sum of squared whitened residuals.
  double cost_before = 0;
  double cost_after = 0;
};

// Depth priors set aside after a solve, by the rule that removed them (a prior over both counts once,
// as `beyond_sigma`), and those that fit again and came back.
struct DepthOutlierStats {
  // Robust scale of |error| / sigma_d over all priors after the solve (see JointAdjusterOptions).
  double residual_scale = 1;
  size_t beyond_sigma = 0;
  size_t beyond_absolute = 0;
  size_t restored = 0;
};

// Each data group's variance factor: its residuals are whitened by its nominal sigma times
// sqrt(factor) (bridge/joint/variance_components.h).
struct VarianceFactors {
  double reprojection = 1, depth = 1, lidar = 1, landmark_lidar = 1;
};

struct SolveStats {
  int round = 0;
  int outlier_iteration = 0;
  TermStats reprojection, depth, lidar, landmark_lidar;
  DepthOutlierStats depth_outliers;
  int num_iterations = 0;
  // Size of the problem as Ceres saw it.
  size_t residual_blocks = 0;
  size_t residuals = 0;
  // Wall time of the whole solve (building the problem, solving, the outlier check), and Ceres' mean
  // time per iteration.
  double seconds = 0;
  double seconds_per_iteration = 0;
  std::string termination;
  // Steps Ceres rejected as invalid (a failed linear solve or evaluation); a solve with any on a
  // problem that leaves parameters undetermined stops with an error naming them.
  int invalid_steps = 0;
  // Observations of landmarks at their camera's centre removed after the solve
  // (bridge/joint/camera_centre_observations.h).
  size_t observations_at_camera_centres = 0;
};

struct PerturbationCurve {
  // x y z [mm] or roll pitch yaw [deg] (about the camera x, y, z axes).
  std::string parameter;
  std::vector<double> offsets;
  // Total cost, everything else at the optimum.
  std::vector<double> costs;
  // The terms that depend on T_e, each on its own: E_l, E_m and E_x (the rest is constant). Their
  // slopes at the optimum say which term pulls T_e which way along the parameter.
  std::vector<double> lidar_costs, landmark_lidar_costs, extrinsic_costs;
};

struct JointAdjustmentSummary {
  std::vector<SolveStats> solves;
  // Residual blocks of the problem rebuilt from the final state, on which the uncertainty and the
  // perturbation curves are evaluated.
  size_t final_reprojection_residuals = 0;
  size_t final_depth_residuals = 0;
  size_t final_lidar_residuals = 0;
  size_t final_landmark_lidar_residuals = 0;
  ExtrinsicUncertainty uncertainty;
  MotionAnalysis motion;
  std::vector<PerturbationCurve> perturbation;
  // Directions of T_e held (hold_unobservable) after a first solve found them unobservable (empty:
  // none); the solves of that first pass are in `solves` too, before those of the held pass.
  std::vector<std::string> held_directions;
  // Whether those directions took the value of JointProblemData::cam_from_lidar_guess (else the
  // start's).
  bool held_at_guess = false;
  // With free_lidar_drive_roll: the axis in the camera frame (zero: E_l saw all of T_e) and E_l's own
  // angle about it at the end (how far the LiDAR motions alone would roll T_e) [deg].
  Eigen::Vector3d lidar_free_axis_in_cam = Eigen::Vector3d::Zero();
  double lidar_free_angle_deg = 0;
  // Per association round of the (last) pass: how far it moved T_e, {deg, mm}.
  std::vector<std::array<double, 2>> extrinsic_change_per_round;
  // The last round's move of T_e per camera axis (rx ry rz [deg], tx ty tz [mm]), and whether the
  // rounds ended because T_e stopped moving (false: max_association_rounds ended them).
  std::array<double, 6> last_round_move{};
  bool association_settled = true;
  // The variance factors in force at the end, and the last estimate's components (empty without
  // estimate_variance_components).
  VarianceFactors variance_factors;
  // With estimate_time_offset: the LiDAR clock's offset from the cameras' [s, or frames without
  // image times].
  std::optional<double> time_offset;
  // With E_m and estimate_oblique_offset: the oblique-view offset delta [rad]
  // (bridge/joint/landmark_lidar_plane_cost.h).
  std::optional<double> oblique_offset_rad;
  // Where E_m measures depth: the stereo depth's bias field c (colmap_ext/depth_prior_cost.h) in
  // inverse depth [1/m], per 1 and per normalised image x and y.
  std::optional<Eigen::Vector3d> depth_prior_bias;
  // E_m's final associations by the camera axis their surface faces (x, y, z).
  std::array<LandmarkPlaneFacing, 3> landmark_lidar_facing;
  std::vector<VarianceComponent> variance_components;
};

// Ceres' mean time per iteration (iteration 0, the initial evaluation, left out); 0 without iterations.
double MeanIterationSeconds(const ceres::Solver::Summary& summary);

class JointAdjuster {
 public:
  explicit JointAdjuster(const JointAdjusterOptions& options);

  // Refines `reconstruction` (poses, landmarks) and `cam_from_lidar` in place; `data` is read during the
  // call only. Prints a line per solve.
  JointAdjustmentSummary Run(const JointProblemData& data,
                             colmap::Reconstruction* reconstruction,
                             colmap::Rigid3d* cam_from_lidar) const;

 private:
  // One adjustment with the given directions of T_e held (projections in the camera frame; zero: none).
  JointAdjustmentSummary RunOnce(const JointProblemData& data,
                                 colmap::Reconstruction* reconstruction,
                                 colmap::Rigid3d* cam_from_lidar,
                                 const Eigen::Matrix3d& held_rotation,
                                 const Eigen::Matrix3d& held_translation) const;

  const JointAdjusterOptions options_;
};

}  // namespace colmap_lidar
