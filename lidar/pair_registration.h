// Registration of two station clouds: BSC matching (mutual nearest neighbours in Hamming space with a
// ratio test), RANSAC on 3-point Kabsch/Umeyama with an edge-length consistency pre-check, a refit on
// all inliers, then point-to-plane ICP. Refuses the edge (accepted = false, with a reason) instead of
// returning a wrong transform.
#pragma once

#include "lidar/point_to_plane_icp.h"
#include "lidar/station_cloud.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace colmap_lidar {

struct PairRegistrationOptions {
  double max_ratio = 0.95;  // best / second-best Hamming distance
  bool mutual = true;       // keep only mutual nearest neighbours
  int ransac_iterations = 200000;
  double inlier_threshold = 0.3;  // keypoint distance after alignment [m]
  double edge_tolerance = 0.2;    // |edge_source - edge_target| of the 3-point sample [m]
  int min_inliers = 6;
  int num_hypotheses = 10;  // distinct RANSAC hypotheses refined by ICP; best overlap wins
  uint64_t seed = 0;
  IcpOptions icp;
  double min_overlap = 0.3;  // ICP inlier fraction of the source
  double max_rmse = 0.05;    // ICP point-to-plane RMSE [m]

  bool Check() const;  // throws std::invalid_argument
};

struct PairRegistration {
  Eigen::Isometry3d target_from_source = Eigen::Isometry3d::Identity();
  size_t num_matches = 0;
  size_t num_inliers = 0;  // RANSAC inliers among the matches (of the chosen hypothesis)
  double overlap = 0;      // ICP overlap ratio
  double rmse = 0;         // ICP RMSE [m]
  bool converged = false;  // ICP converged
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

}  // namespace colmap_lidar
