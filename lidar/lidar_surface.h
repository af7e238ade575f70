// A station's LiDAR surface as the densifier needs it: the cloud (already in the camera frame and cropped
// to the camera's view) thinned to one centroid per small voxel, then each sample moved onto the plane
// fitted to its neighbourhood (PCA; a moving-least-squares projection of order 0; the flattest of the
// sample's own and some shifted neighbourhoods, so that corners stay sharp), with that plane's normal
// and a curvature. A VLP-16's 1-3 cm range noise drops to a few millimetres this way, and the
// curvature says where the surface is flat enough to fill stereo holes from (paper, mapping step).
#pragma once

#include "lidar/point_cloud.h"

#include <Eigen/Core>

#include <vector>

namespace colmap_lidar {

struct LidarSurfaceOptions {
  // voxel edge of the thinning
  double sample_spacing_m = 0.005;
  // PCA neighbourhood radius (normal, position).
  double radius_m = 0.04;
  // A sample with fewer than min_neighbors samples within radius_m is dropped, or with this on it
  // takes 1.5x the distance to its min_neighbors-th nearest sample as its radius, up to
  // max_radius_m. For a rotating LiDAR's sweep from a car (5-30 m away, rings 5-50 cm apart) the
  // 4 cm radius alone dropped nearly every sample. The densifier turns it on where the LiDAR is the
  // only depth (no stereo) and on a moving platform (sweeps); tripods keep radius_m, where growing
  // would let the LiDAR replace far more stereo pixels without a better model.
  bool grow_sparse_neighbourhoods = false;
  double max_radius_m = 0.5;
  // Such a grown neighbourhood whose middle PCA eigenvalue is below this share of the largest is a
  // line (one scan line, its range noise mistaken for a second extent): the radius doubles until it
  // is not, up to max_radius_m, else the sample is dropped.
  double min_planarity = 0.1;
  // Neighbourhood of the curvature (scaled with the sample's PCA radius when that grows). Larger than
  // radius_m: range noise sigma alone gives a flat patch a curvature of about 3 sigma^2 / r^2 (0.19 for a VLP-16's 1 cm at 4 cm, 0.03 at 10 cm).
  double curvature_radius_m = 0.1;
  // Neighbourhoods centred on samples half a radius away that compete with the sample's own; the
  // flattest one gives the plane (0: only the sample's own).
  int num_shifted_neighbourhoods = 8;
  // fewer samples in the radius: the sample is dropped
  int min_neighbors = 8;
  // larger neighbourhoods are subsampled evenly
  int max_neighbors = 96;

  bool Check() const;
};

struct LidarSurface {
  std::vector<Eigen::Vector3d> points;   // on the fitted plane, camera frame
  std::vector<Eigen::Vector3d> normals;  // unit, facing the viewpoint
  // lambda_min / (lambda_1 + lambda_2 + lambda_3) of the curvature_radius_m neighbourhood: 0 on a
  // plane, 1/3 at most.
  std::vector<float> curvature;
  // Mean distance from each sample to its 4 nearest samples: how far its footprint reaches.
  std::vector<float> spacing;

  size_t Size() const { return points.size(); }
};

// `points_in_cam`: the LiDAR points in the camera frame. Normals face the camera (the origin): LiDAR
// and camera see the same side of any surface both see.
LidarSurface BuildLidarSurface(const std::vector<Eigen::Vector3d>& points_in_cam,
                               const LidarSurfaceOptions& options);

}  // namespace colmap_lidar
