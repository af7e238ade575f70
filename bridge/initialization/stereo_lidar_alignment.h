// cam_from_lidar from each station's stereo depth and its own LiDAR cloud (lidar/extrinsic_alignment.h):
// the stereo depth maps of stereo_depth, back-projected through the left camera every few pixels,
// aligned point-to-plane with the station clouds over one shared extrinsic. It needs no motion, so it
// sees what a hand-eye on a car cannot: the roll about the driving direction and the height come from
// the road and the facades. The pose initialiser refines its start (guess or hand-eye) with it.
#pragma once

#include "colmap_ext/station_dataset.h"
#include "lidar/extrinsic_alignment.h"

#include "colmap/geometry/rigid3.h"

#include <string>

namespace colmap_lidar {

struct StereoLidarAlignmentOptions {
  // every `pixel_stride`-th pixel of a depth map, in both directions, or a wider stride that keeps
  // at most `max_pixels_per_station` (a 12 MP map: every 16th)
  int pixel_stride = 4;
  int max_pixels_per_station = 50000;
  // stereo depths used [m]: beyond `max_depth_m` a disparity step is decimetres
  double min_depth_m = 1.0;
  double max_depth_m = 20.0;
  // disparity noise [px] of sigma_d = d^2 / (b f) sigma_p along the ray
  double sigma_disparity_px = 0.5;
  // a pixel whose neighbours' depths differ by more than this fraction is on a depth edge, where
  // block matching fattens the foreground: left out
  double max_neighbour_depth_change = 0.02;
  // fewer associations than this: the alignment is not used
  int min_associations = 1000;
  // LiDAR downsampling before normals and association [m]
  double voxel_size_m = 0.05;
  ExtrinsicAlignmentOptions alignment;

  bool Check() const;
};

struct StereoLidarAlignment {
  ExtrinsicAlignmentResult result;
  colmap::Rigid3d cam_from_lidar;  // the alignment's, or the start if not used
  bool used = false;
  std::string message;  // why not used, or what it changed
  double rotation_change_deg = 0;
  double translation_change_m = 0;
  int num_stations = 0;
};

// Stations of `dataset` (whose cloud_paths may be lidar_registrator's de-skewed / static clouds) with
// a depth map in `depth_path` (stereo_depth's output). Throws naming the file when stereo.json or a
// depth map cannot be read.
StereoLidarAlignment AlignStereoWithLidar(const StationDataset& dataset,
                                          const std::string& depth_path,
                                          const colmap::Rigid3d& initial_cam_from_lidar,
                                          const StereoLidarAlignmentOptions& options);

}  // namespace colmap_lidar
