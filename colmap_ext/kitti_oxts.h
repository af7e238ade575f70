// KITTI raw's OXTS (RTK GPS/IMU) packets and timestamp files (the raw-data development kit's
// dataformat.txt; Geiger et al., IJRR 2013):
//   oxts/data/%010d.txt   one line of 30 values: lat lon [deg], alt [m], roll pitch yaw [rad], then
//                         velocities, accelerations, rates and accuracies (not used here)
//   */timestamps*.txt     "YYYY-MM-DD hh:mm:ss.fffffffff" per frame
// The packets become poses by the development kit's convention: a Mercator projection whose scale
// s = cos(lat_0) is that of the first packet's latitude,
//   t = (s r lon, s r ln tan((90 + lat) / 2), alt)   (r = 6378137 m, angles in radians),
//   R = Rz(yaw) Ry(pitch) Rx(roll),
// and world_from_imu_i = [R_0 | t_0]^-1 [R_i | t_i]: the first packet's IMU frame is the world.
#pragma once

#include "colmap/geometry/rigid3.h"

#include <string>
#include <vector>

namespace colmap_lidar {

struct OxtsPacket {
  double latitude_deg = 0;
  double longitude_deg = 0;
  double altitude_m = 0;
  double roll_rad = 0;
  double pitch_rad = 0;
  double yaw_rad = 0;
};

// Throws std::runtime_error "FILE:LINE: ..." for a missing file, a wrong value count or a NaN.
OxtsPacket ReadOxtsPacket(const std::string& path);

// world_from_imu per packet (see above); empty for no packets.
std::vector<colmap::Rigid3d> WorldFromImuFromOxts(const std::vector<OxtsPacket>& packets);

// Seconds since 1970-01-01 (UTC, no leap seconds) per line of a KITTI timestamp file; strictly
// increasing, at least `min_count` lines. Throws "FILE:LINE: ..." otherwise.
std::vector<double> ReadKittiTimestamps(const std::string& path, size_t min_count = 0);

}  // namespace colmap_lidar
