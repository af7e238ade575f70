// The dense model (paper, mapping step): per station, the stereo depth map refined by the station's LiDAR
// cloud seen through the refined pose and cam_from_lidar (lidar/lidar_depth_refinement.h), then all
// stations back-projected with colour and normals and merged in a voxel grid.
//
// Output (DENSE = output_path; written into DENSE.partial and renamed when complete):
//   DENSE/fused.ply            binary PLY: x y z nx ny nz red green blue, world frame of the model
//   DENSE/lidar_map.ply        every station's LiDAR cloud in the world frame, voxel-downsampled
//   DENSE/densifier.json       per-station counts (stereo kept/confirmed/removed, filled), options
//   DENSE/stereo/previews/<station>.png   where each depth comes from: blue stereo, green LiDAR fill,
//                                         red stereo removed and not filled, black none
//   DENSE/{images, sparse, stereo/depth_maps, stereo/normal_maps, stereo/*.cfg}: COLMAP's dense
//   workspace with the refined maps (colmap_ext/dense_workspace.h)
//
// Memory: stations are streamed; one station's cloud and maps at a time (plus, with the cross-station
// check, its neighbours' depth maps).
#pragma once

#include "colmap_ext/station_dataset.h"
#include "lidar/lidar_depth_refinement.h"
#include "lidar/lidar_surface.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/reconstruction.h"

#include <string>
#include <vector>

namespace colmap_lidar {

struct DensifierOptions {
  // false: the stereo depth maps as they are
  bool refine_with_lidar = true;
  LidarSurfaceOptions surface;
  LidarDepthRefinementOptions refinement;
  // LiDAR points outside this z range in the camera frame are not projected.
  double min_depth_m = 0.3;
  double max_depth_m = 30;
  // Cross-station consistency, as in COLMAP's fusion: a pixel is kept only if its point agrees with the
  // depth maps of at least this many other stations (0 = off). Compared: the stations that see most of
  // its depth map, at most max_neighbor_views of them.
  int min_consistent_views = 0;
  int max_neighbor_views = 6;
  double consistency_abs_m = 0.01;
  double consistency_rel = 0.005;
  // merge of fused.ply
  double fused_voxel_size_m = 0.001;
  // lidar_map.ply
  double lidar_map_voxel_size_m = 0.01;

  bool Check() const;
};

struct StationDensification {
  std::string station;
  size_t lidar_points_in_view = 0;
  LidarDepthRefinementStats refinement;
  size_t inconsistent = 0;  // dropped by the cross-station check
  size_t points = 0;        // back-projected into fused.ply's grid
  double seconds = 0;
};

struct DensifierSummary {
  std::vector<StationDensification> stations;
  size_t fused_points = 0;
  size_t lidar_map_points = 0;
  double seconds = 0;
};

// Stations are the registered images named like the dataset's left images ("left/<station>.png").
// `depth_path` empty: no image depth (a monocular rig); the LiDAR fills flat layers alone.
// Throws std::runtime_error naming the station and file for a missing or mis-sized depth map, an
// unreadable cloud or image; nothing is left at output_path then.
DensifierSummary Densify(const colmap::Reconstruction& reconstruction,
                         const colmap::Rigid3d& cam_from_lidar,
                         const StationDataset& dataset,
                         const std::string& depth_path,
                         const std::string& output_path,
                         const DensifierOptions& options);

}  // namespace colmap_lidar
