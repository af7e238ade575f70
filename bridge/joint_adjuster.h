// The seed's back end: ONE Levenberg-Marquardt problem over camera poses T, landmarks L and the
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
//   (bridge/lidar_point_to_plane_cost.h).
// - E_f = COLMAP's reprojection residual in pixels (sigma_p = 1 px); E_d = the depth-prior residual
//   (colmap_ext/depth_prior_cost.h), z-depth with sigma_d = d^2/(b f) sigma_p.
// - Gauge: the first station's (smallest image_id's) pose is constant. Metric scale comes from the depth
//   priors and the LiDAR; nothing else is fixed.
//
// Injection (COLMAP 3.10): BundleAdjuster::SetUpProblem() -> Problem() -> add our residual blocks ->
// SetUpSolverOptions() -> ceres::Solve. BundleAdjuster::Solve() is never called (it would rebuild the
// problem). COLMAP's problem does not own loss functions; this class owns every loss it passes.
#pragma once

#include "bridge/extrinsic_observability.h"
#include "colmap_ext/extension_database.h"
#include "lidar/point_to_plane_association.h"
#include "lidar/station_cloud.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/reconstruction.h"

#include <array>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace colmap_lidar {

// The seed's three comparisons.
enum class JointMode {
  kJoint,          // T_e refined with everything else
  kPrecalibrated,  // T_e held constant
  kStereoOnly,     // no LiDAR term (weight 0), T_e constant
};
JointMode JointModeFromName(const std::string& name);  // joint | precalibrated | stereo_only
std::string JointModeName(JointMode mode);

struct JointAdjusterOptions {
  JointMode mode = JointMode::kJoint;
  // Weights: sigma_p = 1 px is COLMAP's; sigma_d comes with each depth prior.
  double sigma_lidar_m = 0.02;  // seed: 0.02 - 0.1 m
  double depth_weight = 1.0;    // w_c of E_d (E_f keeps weight 1)
  double lidar_weight = 1.0;    // w_l
  std::string loss = "none";    // none | huber | cauchy (on every term; off in the seed)
  double loss_scale = 1.0;      // in units of the whitened residual
  // Outliers (zero weight until none remain).
  double max_reprojection_error_px = 3.0;
  double max_depth_error_m = 0.01;
  double max_point_to_plane_m = 0.1;
  int max_outlier_iterations = 10;
  // ICP-like re-association of the LiDAR observations.
  int num_association_rounds = 4;
  AssociationOptions association;  // num_samples per directed pair; max_distance = final gate
  double initial_association_distance_m =
      0.5;  // gate of round 0, halved per round down to max_distance
  // Extrinsic degrees of freedom held constant in joint mode (users ask for it): rotation as a whole,
  // translation per camera axis.
  bool hold_rotation = false;
  std::array<bool, 3> hold_translation = {false, false, false};
  // Weak prior on T_e's translation at its initial value (bridge/extrinsic_prior_cost.h): keeps an
  // unobservable direction where it started instead of letting it drift; 0 = off.
  double extrinsic_prior_sigma_m = 1.0;
  int max_num_iterations = 100;
  ObservabilityOptions observability;

  bool Check() const;
};

// What the joint problem needs besides COLMAP's reconstruction.
struct JointProblemData {
  // Depth priors per image, keyed by point2D_idx.
  std::unordered_map<colmap::image_t, std::unordered_map<colmap::point2D_t, DepthPrior>>
      depth_priors;
  // Each station's cloud (lidar frame, normals, k-d tree), keyed by image_id; not owned.
  std::map<colmap::image_t, const StationCloud*> clouds;
  // The pose graph A_c v A_l as unordered image pairs; LiDAR observations are drawn in both directions.
  std::vector<std::pair<colmap::image_t, colmap::image_t>> pairs;
};

struct TermStats {
  size_t num_observations = 0;
  size_t num_outliers = 0;  // given weight zero so far
  double cost_before = 0;   // 1/2 sum of squared whitened residuals
  double cost_after = 0;
};

struct SolveStats {
  int round = 0;
  int outlier_iteration = 0;
  TermStats reprojection, depth, lidar;
  int num_iterations = 0;
  double seconds = 0;
  std::string termination;
};

struct PerturbationCurve {
  std::string parameter;  // x y z [mm] or roll pitch yaw [deg] (about the camera x, y, z axes)
  std::vector<double> offsets;
  std::vector<double> costs;  // total cost, everything else at the optimum
};

struct JointAdjustmentSummary {
  std::vector<SolveStats> solves;
  ExtrinsicUncertainty uncertainty;
  MotionAnalysis motion;
  std::vector<PerturbationCurve> perturbation;
};

class JointAdjuster {
 public:
  JointAdjuster(const JointAdjusterOptions& options, const JointProblemData& data);

  // Refines `reconstruction` (poses, landmarks) and `cam_from_lidar` in place. Prints a line per solve.
  JointAdjustmentSummary Run(colmap::Reconstruction* reconstruction,
                             colmap::Rigid3d* cam_from_lidar);

 private:
  struct Observation {
    colmap::image_t target = 0, source = 0;
    PointToPlaneObservation data;
    bool outlier = false;
  };
  std::vector<Observation> Associate(const colmap::Reconstruction& reconstruction,
                                     const colmap::Rigid3d& cam_from_lidar,
                                     double max_distance) const;

  const JointAdjusterOptions options_;
  const JointProblemData& data_;
};

}  // namespace colmap_lidar
