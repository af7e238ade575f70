// A ray-cast street for odometry tests: axis-aligned boxes (ground, facade blocks with gaps, poles,
// parked cars) scanned by a rotating multi-beam LiDAR from a moving platform. Each azimuth column is
// fired from the platform's pose at its instant and written in that instant's LiDAR frame (raw,
// not motion-compensated), as a driver writes sweeps. Header-only, Eigen only.
#pragma once

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace colmap_lidar {
namespace testing {

struct Box {
  Eigen::Vector3d lo, hi;
};

// Ground, facades on both sides of a street along x (blocks 6-14 m long with 2-4 m gaps, set back
// 0-1.5 m from y = +-8 m), poles and parked cars; `walls_only`: two endless facades and the ground
// (a street that constrains nothing along x).
inline std::vector<Box> StreetBoxes(uint32_t seed, double length_m, bool walls_only = false) {
  std::vector<Box> boxes = {{{-50, -30, -0.2}, {length_m + 50, 30, 0}}};
  if (walls_only) {
    boxes.front() = {{-1000, -30, -0.2}, {length_m + 1000, 30, 0}};
    boxes.push_back({{-1000, 8, 0}, {length_m + 1000, 9, 12}});
    boxes.push_back({{-1000, -9, 0}, {length_m + 1000, -8, 12}});
    return boxes;
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  for (const double side : {1.0, -1.0}) {
    for (double x = -40; x < length_m + 40;) {
      const double block = 6 + 8 * unit(rng), setback = 1.5 * unit(rng), height = 6 + 9 * unit(rng);
      const double y0 = side * (8 + setback), y1 = side * (8 + setback + 10);
      boxes.push_back({{x, std::min(y0, y1), 0}, {x + block, std::max(y0, y1), height}});
      x += block + 2 + 2 * unit(rng);
    }
    for (double x = -30; x < length_m + 30; x += 9 + 6 * unit(rng)) {
      const double y = side * (6.5 + 0.5 * unit(rng));
      boxes.push_back({{x, y - 0.1, 0}, {x + 0.2, y + 0.1, 4 + 2 * unit(rng)}});
    }
    for (double x = -20; x < length_m + 20; x += 7 + 10 * unit(rng)) {
      const double y = side * 4.5;
      boxes.push_back({{x, y - 0.9, 0}, {x + 4.2, y + 0.9, 1.5}});
    }
  }
  return boxes;
}

// Distance along the unit ray from `origin` to the nearest box, or infinity (slab method).
inline double CastRay(const std::vector<Box>& boxes,
                      const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& direction) {
  double best = std::numeric_limits<double>::infinity();
  for (const Box& box : boxes) {
    double t_near = 0, t_far = best;
    bool hit = true;
    for (int a = 0; a < 3 && hit; ++a) {
      if (std::abs(direction[a]) < 1e-12) {
        hit = origin[a] >= box.lo[a] && origin[a] <= box.hi[a];
        continue;
      }
      double t0 = (box.lo[a] - origin[a]) / direction[a],
             t1 = (box.hi[a] - origin[a]) / direction[a];
      if (t0 > t1) std::swap(t0, t1);
      t_near = std::max(t_near, t0);
      t_far = std::min(t_far, t1);
      hit = t_near <= t_far;
    }
    if (hit && t_near > 0.01) best = t_near;
  }
  return best;
}

// The platform's LiDAR pose world_from_lidar at time t [s]: 1.8 m above the street, driving along
// x at `speed` m/s with a slow weave of the heading.
inline Eigen::Isometry3d DrivePose(double t, double speed) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const double heading = 0.08 * std::sin(0.25 * t);
  pose.linear() = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // y: the integral of speed * heading.
  pose.translation() = Eigen::Vector3d(speed * t, speed * 0.32 * (1 - std::cos(0.25 * t)), 1.8);
  return pose;
}

// One sweep of `beams` beams from `top_deg` to `bottom_deg` elevation (an HDL-64: +2 to -24.8; a
// VLP-16: +15 to -15) and `columns` azimuths, starting behind
// the platform and turning counter-clockwise over [t_mid - period / 2, t_mid + period / 2), each
// column fired from that instant's pose and written in that instant's LiDAR frame; range noise
// sigma `noise_m`.
inline std::vector<Eigen::Vector3d> ScanSweep(const std::vector<Box>& boxes,
                                              double t_mid,
                                              double period,
                                              double speed,
                                              int beams,
                                              int columns,
                                              double noise_m,
                                              std::mt19937* rng,
                                              double top_deg = 15,
                                              double bottom_deg = -15) {
  std::normal_distribution<double> noise(0, noise_m);
  std::vector<Eigen::Vector3d> points;
  for (int c = 0; c < columns; ++c) {
    const double fraction = (c + 0.5) / columns;
    const Eigen::Isometry3d pose = DrivePose(t_mid + (fraction - 0.5) * period, speed);
    const double azimuth = M_PI + 2 * M_PI * fraction;
    for (int b = 0; b < beams; ++b) {
      const double elevation = (top_deg + (bottom_deg - top_deg) * b / (beams - 1)) * M_PI / 180;
      const Eigen::Vector3d direction(std::cos(elevation) * std::cos(azimuth),
                                      std::cos(elevation) * std::sin(azimuth),
                                      std::sin(elevation));
      const double range = CastRay(boxes, pose.translation(), pose.linear() * direction);
      if (range > 100) continue;
      points.push_back((range + (noise_m > 0 ? noise(*rng) : 0.0)) * direction);
    }
  }
  return points;
}

}  // namespace testing
}  // namespace colmap_lidar
