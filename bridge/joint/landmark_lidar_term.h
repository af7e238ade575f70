// Associations of the landmark-to-LiDAR-plane term E_m (bridge/joint/landmark_lidar_plane_cost.h):
// each observation of a landmark in image i is paired with the nearest planar point q (and its normal n) of
// station i's LiDAR cloud, found through the current cam_from_world_i and T_e = cam_from_lidar.
// Re-associated every round of the joint adjustment, like the LiDAR-to-LiDAR term.
#pragma once

#include "lidar/station_cloud.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/reconstruction.h"

#include <Eigen/Core>

#include <array>
#include <map>
#include <vector>

namespace colmap_lidar {

struct LandmarkPlaneObservation {
  colmap::image_t image_id = 0;
  colmap::point3D_t point3D_id = 0;
  Eigen::Vector3d point_in_lidar;   // q, station i's LiDAR frame
  Eigen::Vector3d normal_in_lidar;  // n, unit
  bool outlier = false;
};

// Every landmark observation of an image with a cloud whose nearest cloud point lies within
// `max_distance` and has a curvature at most `max_curvature` (a planar neighbourhood). Parallel over
// images; the trees are the clouds' own.
std::vector<LandmarkPlaneObservation> AssociateLandmarksWithLidar(
    const colmap::Reconstruction& reconstruction,
    const std::map<colmap::image_t, const StationCloud*>& clouds,
    const colmap::Rigid3d& cam_from_lidar,
    double max_distance,
    double max_curvature);

// n^T (lidar_i_from_world X - q) [m] under the reconstruction's current state; NaN when the landmark
// or the image is no longer in the reconstruction.
double LandmarkPlaneDistance(const LandmarkPlaneObservation& observation,
                             const colmap::Reconstruction& reconstruction,
                             const colmap::Rigid3d& cam_from_lidar);

// E_m's associations in force by the camera axis their surface faces (the largest component of the
// normal in the camera frame): a translation of cam_from_lidar along a camera axis changes only the
// residuals of surfaces facing that axis, so on a drive the vertical translation rests on the ground
// (axis y). Signed residuals are positive in front of the LiDAR surface (normals face the sensor).
struct LandmarkPlaneFacing {
  size_t num_observations = 0;
  double mean_residual_m = 0;
  double rms_residual_m = 0;
};
std::array<LandmarkPlaneFacing, 3> SummariseByFacingAxis(
    const std::vector<LandmarkPlaneObservation>& observations,
    const colmap::Reconstruction& reconstruction,
    const colmap::Rigid3d& cam_from_lidar);

}  // namespace colmap_lidar
