// Image edges A_c of the pose graph: for each image pair COLMAP verified, the metric relative pose
// cam_i_from_cam_j from the inlier matches that carry depth priors on both sides: each such match gives
// a 3D-3D correspondence (the keypoint's ray scaled to its prior z-depth in either camera); 3-point
// RANSAC with Umeyama (no scale: the depths are metric), refined on the inliers.
#pragma once

#include "colmap_ext/extension_database.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/database.h"

#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

namespace colmap_lidar {

struct ImagePairPoseOptions {
  int min_inliers = 20;
  // A correspondence is an inlier if the two 3D points agree within this fraction of their depth.
  double max_relative_error = 0.02;
  int num_ransac_iterations = 500;
  uint64_t seed = 0;

  bool Check() const;
};

struct ImagePairPose {
  colmap::image_t image_i = colmap::kInvalidImageId;
  colmap::image_t image_j = colmap::kInvalidImageId;
  colmap::Rigid3d cam_i_from_cam_j;
  int num_correspondences = 0;  // matches with depth priors on both sides
  int num_inliers = 0;
  double rms_m = 0;  // of the inliers
};

using DepthPriorsByImage =
    std::unordered_map<colmap::image_t, std::unordered_map<colmap::point2D_t, DepthPrior>>;

std::vector<ImagePairPose> EstimateImagePairPoses(const colmap::Database& database,
                                                  const DepthPriorsByImage& depth_priors,
                                                  const ImagePairPoseOptions& options);

// COLMAP's two-view pose of a verified pair (EstimateTwoViewGeometryPose on its inlier matches):
// geometry.cam2_from_cam1 with a unit translation; the keypoints in pixels. Borrowed for the visit.
struct TwoViewPose {
  colmap::image_t image_id1, image_id2;
  const colmap::Camera& camera1;
  const colmap::Camera& camera2;
  const std::vector<Eigen::Vector2d>& keypoints1;
  const std::vector<Eigen::Vector2d>& keypoints2;
  const colmap::TwoViewGeometry& geometry;
};

// Visits every pair COLMAP verified with at least `min_inliers` inlier matches whose pose COLMAP can
// estimate, in the database's order; with `wanted`, only the pairs (image_id1, image_id2) it accepts
// (before their pose is estimated).
void ForEachTwoViewPose(
    const colmap::Database& database,
    int min_inliers,
    const std::function<void(const TwoViewPose&)>& visit,
    const std::function<bool(colmap::image_t, colmap::image_t)>& wanted = nullptr);

// Monocular image edges: for each image pair COLMAP verified with at least `min_inliers` inlier
// matches, the relative rotation and the translation *direction* (unit norm: one camera has no scale)
// from COLMAP's own two-view pose estimation (EstimateTwoViewGeometryPose on the inlier matches).
// Pairs whose pose COLMAP cannot estimate are left out.
std::vector<ImagePairPose> EstimateImagePairDirections(const colmap::Database& database,
                                                       int min_inliers);

}  // namespace colmap_lidar
