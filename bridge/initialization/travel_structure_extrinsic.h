// cam_from_lidar of a platform that drives without turning, from what both sensors see of the
// drive: the direction of travel and the scene's structure. A hand-eye needs rotations about two
// axes (or, for a car, about one with a drive that turns); a straight drive gives none. Here:
// 1. Travel: each image pair COLMAP verified gives the camera's translation direction (two-view
//    geometry) and the LiDAR poses the LiDAR's; for a motion that hardly turns, a_k = R_e b_k. The
//    robust means of both (pairs beyond `max_direction_deviation_deg` of the mean left out) give R_0,
//    the rotation that takes the LiDAR's travel direction onto the camera's. The roll about it is free.
// 2. Structure: the inlier matches of those pairs, triangulated in the first camera's frame with the
//    baseline made metric by the LiDAR motion (|b_k|), are camera-frame points of known depth noise.
//    The roll about the travel direction is searched over the whole turn against each station's own
//    cloud (lidar/axis_roll_search.h), then the full cam_from_lidar is aligned point-to-plane
//    (lidar/extrinsic_alignment.h), whose covariance comes with it.
// The result is a start for the joint adjustment, not a measurement: it uses the data the joint
// problem uses again.
#pragma once

#include "colmap_ext/station_dataset.h"
#include "lidar/axis_roll_search.h"
#include "lidar/extrinsic_alignment.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/database.h"

#include <map>
#include <string>

namespace colmap_lidar {

struct TravelStructureOptions {
  // image pairs with fewer inlier matches are not used
  int min_inliers = 30;
  // LiDAR motions shorter than this carry no direction [m]
  double min_translation_m = 0.3;
  // LiDAR motions rotating more are not a translation along the drive (a_k = R_e b_k holds up to
  // (R_A - I) t_e) [deg]
  double max_rotation_deg = 3.0;
  // a pair whose camera or LiDAR direction is farther from the robust mean is left out [deg]
  double max_direction_deviation_deg = 5.0;
  // at least this many pairs agree on the travel direction
  int min_direction_pairs = 3;
  // triangulated points: rays meeting at less than this angle are left out [deg]
  double min_triangulation_angle_deg = 1.0;
  // keypoint noise [px] of each point's depth sigma
  double sigma_keypoint_px = 1.0;
  // points farther are left out [m]
  double max_depth_m = 40.0;
  // LiDAR downsampling before normals and association [m]
  double voxel_size_m = 0.1;
  // fewer associations in the final alignment: no result
  int min_associations = 1000;
  AxisRollSearchOptions roll_search;
  ExtrinsicAlignmentOptions alignment;

  bool Check() const;
};

struct TravelStructureExtrinsic {
  bool valid = false;
  std::string message;  // why not valid, or a one-line summary
  colmap::Rigid3d cam_from_lidar;
  Eigen::Vector3d travel_in_cam = Eigen::Vector3d::Zero();  // unit
  Eigen::Vector3d travel_in_lidar = Eigen::Vector3d::Zero();
  int num_direction_pairs = 0;   // agreeing on the travel direction
  double direction_rms_deg = 0;  // their camera directions about the mean
  int num_stations = 0;          // with triangulated points
  AxisRollSearchResult roll;
  ExtrinsicAlignmentResult alignment;
};

// `world_from_lidar`: the LiDAR poses by station name (lidar_registrator's); `image_of_station`: the
// database's image of each station. Throws naming the file when a station cloud cannot be read.
TravelStructureExtrinsic EstimateExtrinsicFromTravelAndStructure(
    const colmap::Database& database,
    const StationDataset& dataset,
    const std::map<std::string, colmap::Rigid3d>& world_from_lidar,
    const std::map<std::string, colmap::image_t>& image_of_station,
    const TravelStructureOptions& options);

}  // namespace colmap_lidar
