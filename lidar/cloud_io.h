// Reading and writing point clouds.
//
// Read: PCD (ascii, binary, binary_compressed; through PCL), PLY (ascii, binary little/big endian),
// KITTI .bin (float32 x y z intensity) and plain text .xyz/.txt (x y z [intensity] per line).
// Every reader throws std::runtime_error naming the file for a missing, empty, truncated, mis-typed or
// all-non-finite file; NaN/Inf points inside an otherwise good file are dropped and counted.
// Write: .pcd (binary, x y z [intensity] [normal_x normal_y normal_z] [rgb]) and .ply (binary little
// endian, x y z [nx ny nz] [red green blue] [intensity]). Writes go to a temporary file that is renamed
// into place, so a failed write never leaves a half-written cloud.
#pragma once

#include "lidar/point_cloud.h"

#include <string>

namespace colmap_lidar {

struct CloudReadStats {
  size_t num_read = 0;                // points in the file
  size_t num_dropped_non_finite = 0;  // NaN/Inf points dropped
};

PointCloud ReadPointCloud(const std::string& path, CloudReadStats* stats = nullptr);

// A station's LiDAR cloud: ReadPointCloud, then a check that it is in the sensor's frame in metres.
// The median range from the sensor of any terrestrial LiDAR is far below kMaxMedianRangeM; a cloud
// above it is in another unit (millimetres) or in a world frame, and is refused with the figure.
constexpr double kMaxMedianRangeM = 500;
PointCloud ReadStationCloud(const std::string& path, CloudReadStats* stats = nullptr);

void WritePointCloud(const std::string& path, const PointCloud& cloud);

}  // namespace colmap_lidar
