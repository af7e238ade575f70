// Points of moving objects (cars driving past a moving platform, people walking past a station) found
// by free space: a LiDAR return means the space between the sensor and the return was empty when it
// was measured. A point p of cloud i lies where another registered cloud j saw through: j's nearest
// return in the directions around p (seen from j's sensor) is farther than p. In a static world that
// cannot happen; it happens where something stood at i's time and had left at j's.
//
// Beyond the paper, which captured a static specimen. On a street, the LiDAR-to-LiDAR association
// pairs a car's surface with the same car moved, and the joint adjustment then fits the car's motion
// into the sensor poses and cam_from_lidar.
//
// The test is one-sided on purpose: a point is never removed because another cloud did not see it
// (occlusion, field of view) but only because another cloud saw beyond it. The smallest range over
// the cells around the direction (not the cell's own) keeps a surface seen at a grazing angle (the
// road) and the rims of near objects from being taken for free space.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace colmap_lidar {

struct MovingPointOptions {
  // Cell size of each cloud's spherical range image [deg]; 0: automatic per cloud
  // (SphericalRangeImage::AutomaticResolution).
  double angular_resolution_deg = 0.0;
  // Each cloud is tested against up to this many clouds before and after it (in the given order,
  // e.g. time) of the same registration component.
  int num_neighbour_clouds = 3;
  // Cloud j saw through p when its nearest return around p's direction lies at least
  // margin_m + margin_ratio * (p's range from j) beyond p: more than the registration error and the
  // range noise.
  double margin_m = 0.3;
  double margin_ratio = 0.02;
  // The returns around p's direction: cells within this many cells of p's cell (1: 3 x 3).
  int neighbourhood_cells = 1;
  // A point is moving when at least this many clouds saw through it.
  int min_votes = 1;
  // Returns nearer than this to their sensor (the platform itself) are left out [m].
  double min_range_m = 0.5;

  bool Check() const;
};

// flags[i][k] is 1 when point k of cloud i is where another cloud saw free space. Cloud i is
// `points_in_lidar[i]` in its sensor's frame (the sensor at the origin; a de-skewed sweep: at the
// middle of the sweep) with the registered pose `world_from_lidar[i]`; only clouds of the same
// `component[i]` are compared (empty: all one component). Clouds are processed in parallel.
std::vector<std::vector<uint8_t>> FlagMovingPoints(
    const std::vector<const std::vector<Eigen::Vector3d>*>& points_in_lidar,
    const std::vector<Eigen::Isometry3d>& world_from_lidar,
    const std::vector<int>& component,
    const MovingPointOptions& options);

}  // namespace colmap_lidar
