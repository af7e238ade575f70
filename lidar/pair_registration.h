// Registration of two station clouds: BSC matching (mutual nearest neighbours in Hamming space with a
// ratio test), RANSAC on 3-point Kabsch/Umeyama with an edge-length consistency pre-check, a refit on
// all inliers, then point-to-plane ICP (also from the identity). Gates from the data: the ICP RMSE
// against the clouds' own plane noise, the overlap, and the constraint analysis of the ICP Hessian.
// Refuses the edge (accepted = false, with a reason) instead of returning a wrong transform.
#pragma once

#include "lidar/point_to_plane_icp.h"
#include "lidar/registration_quality.h"
#include "lidar/station_cloud.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace colmap_lidar {

struct PairRegistrationOptions {
  // best / second-best Hamming distance
  double max_ratio = 0.95;
  // keep only mutual nearest neighbours
  bool mutual = true;
  int ransac_iterations = 200000;
  // keypoint distance after alignment [m]
  double inlier_threshold = 0.3;
  // |edge_source - edge_target| of the 3-point sample [m]
  double edge_tolerance = 0.2;
  int min_inliers = 6;
  // distinct RANSAC hypotheses refined by ICP; best overlap wins
  int num_hypotheses = 10;
  // ICP from the identity as one more hypothesis: consecutive sweeps of a moving platform (and
  // stations close together) often have too few BSC inliers but start inside ICP's basin.
  bool try_identity = true;
  uint64_t seed = 0;
  IcpOptions icp;
  // Coarse to fine: every hypothesis is first refined by ICP on at most this many source points (0:
  // every hypothesis at icp.max_source_points), and only the `num_refined` best by that overlap are
  // refined at full resolution from there. Most of a pair's time is ICP's nearest-neighbour queries.
  size_t screening_source_points = 3000;
  int num_refined = 2;
  // ICP inlier fraction of the source
  double min_overlap = 0.3;
  // The ICP point-to-plane RMSE must not exceed this multiple of the clouds' own plane noise
  // (StationCloud::plane_noise_rms; sqrt of the mean of both squares).
  double max_rmse_to_noise = 2.0;
  // An absolute RMSE cap [m]; 0 = none (the relative gate above adapts to the sensor).
  double max_rmse = 0;
  // Constraint analysis of the final ICP (AnalyseConstraints): below `min_constraint_ratio` the
  // pair is refused; below `weak_constraint_ratio` it is accepted as degenerate, its weakest
  // direction named and carried with its (small) information into the pose graph.
  double min_constraint_ratio = 1e-4;
  double weak_constraint_ratio = 0.02;

  bool Check() const;
};

struct PairRegistration {
  Eigen::Isometry3d target_from_source = Eigen::Isometry3d::Identity();
  size_t num_matches = 0;
  // RANSAC inliers among the matches; from the identity: the matches that agree with the alignment.
  size_t num_inliers = 0;
  bool from_identity = false;  // the accepted alignment started from the identity
  double overlap = 0;          // ICP overlap ratio
  double rmse = 0;             // ICP RMSE [m]
  double noise_rms = 0;        // the pair's expected RMSE from the clouds' own plane noise [m]
  bool converged = false;      // ICP converged
  // Final ICP Hessian [omega, t] (IcpResult::hessian) and its analysis.
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  ConstraintAnalysis constraints;
  bool degenerate = false;  // accepted with a weakly constrained direction
  bool accepted = false;
  std::string reason;  // why not accepted
};

// Matches of source features to target features: (source index, target index).
std::vector<std::pair<size_t, size_t>> MatchBscFeatures(const std::vector<BscFeature>& source,
                                                        const std::vector<BscFeature>& target,
                                                        double max_ratio,
                                                        bool mutual);

PairRegistration RegisterStationClouds(const StationCloud& source,
                                       const StationCloud& target,
                                       const PairRegistrationOptions& options);

// Point-to-plane ICP from `target_from_source_guess` alone (e.g. a constant-velocity prediction for
// sweeps), judged by the same gates.
PairRegistration RegisterFromGuess(const StationCloud& source,
                                   const StationCloud& target,
                                   const Eigen::Isometry3d& target_from_source_guess,
                                   const PairRegistrationOptions& options);

}  // namespace colmap_lidar
