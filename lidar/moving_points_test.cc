#include "lidar/moving_points.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace colmap_lidar {
namespace {

struct Box {
  Eigen::Vector3d lo, hi;
  bool moving = false;
};

// Distance along the unit ray to the box's surface seen from outside (slab method; `axis`: the
// normal axis of the face hit); inf: missed.
double HitBox(const Eigen::Vector3d& origin,
              const Eigen::Vector3d& direction,
              const Box& box,
              int* axis) {
  double near = 0, far = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(direction[a]) < 1e-12) {
      if (origin[a] < box.lo[a] || origin[a] > box.hi[a]) {
        return std::numeric_limits<double>::infinity();
      }
      continue;
    }
    double t0 = (box.lo[a] - origin[a]) / direction[a], t1 = (box.hi[a] - origin[a]) / direction[a];
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > near) near = t0, *axis = a;
    far = std::min(far, t1);
  }
  return near <= far && near > 0 ? near : std::numeric_limits<double>::infinity();
}

enum class Surface { kStatic, kMovingAlongNormal, kMovingAlongItself };

struct Sweep {
  std::vector<Eigen::Vector3d> points_in_lidar;
  std::vector<Surface> surface;
};

// A street: the road (z = 0), a facade on each side, a parked car and a car driving at 6 m/s; the
// sensor 1.7 m above the road at x = `sensor_x`, a 0.4 deg grid of rays from -24 to +10 deg of
// elevation, 1 cm range noise. At time t the driving car has moved 6 t m.
Sweep CastSweep(double sensor_x, double time_s, std::mt19937* rng) {
  const std::vector<Box> boxes = {{{-50, 8, 0}, {80, 14, 12}},
                                  {{-50, -14, 0}, {80, -8, 12}},
                                  {{15, 4.5, 0}, {19.3, 6.3, 1.5}},
                                  {Eigen::Vector3d(10 + 6 * time_s, -2.7, 0),
                                   Eigen::Vector3d(14.4 + 6 * time_s, -0.9, 1.5),
                                   true}};
  const Eigen::Vector3d origin(sensor_x, 0, 1.7);
  std::normal_distribution<double> noise(0, 0.01);
  Sweep sweep;
  const double step = 0.4 * M_PI / 180;
  for (double elevation = -24 * M_PI / 180; elevation < 10 * M_PI / 180; elevation += step) {
    for (double azimuth = -M_PI; azimuth < M_PI; azimuth += step) {
      const Eigen::Vector3d direction(std::cos(elevation) * std::cos(azimuth),
                                      std::cos(elevation) * std::sin(azimuth),
                                      std::sin(elevation));
      double range = direction.z() < 0 ? -origin.z() / direction.z() : 1e9;
      Surface surface = Surface::kStatic;
      for (const Box& box : boxes) {
        int axis = -1;
        const double t = HitBox(origin, direction, box, &axis);
        if (t >= range) continue;
        range = t;
        surface = !box.moving ? Surface::kStatic
                  : axis == 0 ? Surface::kMovingAlongNormal
                              : Surface::kMovingAlongItself;
      }
      if (range > 60) continue;
      sweep.points_in_lidar.push_back((range + noise(*rng)) * direction);
      sweep.surface.push_back(surface);
    }
  }
  return sweep;
}

// Shares of the points flagged, by surface.
struct Counts {
  double along_normal = 0, along_itself = 0, still = 0;
};

// Five sweeps of a platform driving at 10 m/s (10 Hz), poses off by `pose_error_m` along x.
Counts RunStreet(double pose_error_m, const MovingPointOptions& options) {
  std::mt19937 rng(7);
  std::vector<Sweep> sweeps;
  std::vector<Eigen::Isometry3d> world_from_lidar;
  for (int i = 0; i < 5; ++i) {
    sweeps.push_back(CastSweep(1.0 * i, 0.1 * i, &rng));
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(1.0 * i + (i % 2 ? pose_error_m : 0), 0, 1.7);
    world_from_lidar.push_back(pose);
  }
  std::vector<const std::vector<Eigen::Vector3d>*> points;
  for (const Sweep& s : sweeps) points.push_back(&s.points_in_lidar);
  const auto flags = FlagMovingPoints(points, world_from_lidar, {}, options);
  // The last sweep's car is where no later sweep looked: only sweeps with a later one are counted.
  double count[3] = {0, 0, 0}, flagged[3] = {0, 0, 0};
  for (size_t i = 0; i + 1 < sweeps.size(); ++i) {
    EXPECT_EQ(flags[i].size(), sweeps[i].points_in_lidar.size());
    for (size_t k = 0; k < flags[i].size(); ++k) {
      count[int(sweeps[i].surface[k])] += 1;
      flagged[int(sweeps[i].surface[k])] += flags[i][k];
    }
  }
  EXPECT_GT(count[1], 300);
  EXPECT_GT(count[2], 300);
  const Counts counts{flagged[1] / count[1], flagged[2] / count[2], flagged[0] / count[0]};
  std::cout << "pose error " << pose_error_m << " m: flagged " << counts.along_normal
            << " of the driving car's rear, " << counts.along_itself << " of its sides and top, "
            << counts.still << " of the static points" << std::endl;
  return counts;
}

// The car's rear moves along its normal and is flagged. Its sides and top slide along themselves:
// free space sees only the parts that moved off (the rest is where a surface was at both times), and
// those parts bias no point-to-plane residual.
TEST(MovingPoints, FlagsTheDrivingCarAndKeepsTheStreet) {
  const Counts counts = RunStreet(0.0, MovingPointOptions());
  EXPECT_GE(counts.along_normal, 0.75);  // measured 0.89 (1.0 - rims - the 0.6 m move of one frame)
  EXPECT_GE(counts.along_itself, 0.15);  // measured 0.25
  EXPECT_LE(counts.still, 1e-4);         // measured 0
}

// A registration 10 cm off (several times the registered error on a street) must not turn the
// road or the facades into moving points.
TEST(MovingPoints, ToleratesRegistrationError) {
  const Counts counts = RunStreet(0.1, MovingPointOptions());
  EXPECT_GE(counts.along_normal, 0.75);  // measured 0.85
  EXPECT_LE(counts.still, 1e-4);         // measured 0
}

// Without a margin the range noise alone would carve the road.
TEST(MovingPoints, TheMarginKeepsNoiseFromVoting) {
  MovingPointOptions options;
  options.margin_m = 1e-6;
  options.margin_ratio = 0;
  options.neighbourhood_cells = 0;
  EXPECT_GT(RunStreet(0.0, options).still, 0.01);
}

TEST(MovingPoints, RefusesBadInput) {
  MovingPointOptions options;
  options.min_votes = 0;
  const std::vector<Eigen::Vector3d> cloud = {Eigen::Vector3d(1, 0, 0)};
  EXPECT_THROW(FlagMovingPoints({&cloud}, {Eigen::Isometry3d::Identity()}, {}, options),
               std::invalid_argument);
  EXPECT_THROW(FlagMovingPoints({&cloud}, {}, {}, MovingPointOptions()), std::invalid_argument);
}

// Clouds of different registration components are never compared: a sweep that sees through the
// other's point counts only when both are in one component.
TEST(MovingPoints, ComparesOnlyWithinAComponent) {
  const std::vector<Eigen::Vector3d> near = {Eigen::Vector3d(5, 0, 0)};
  std::vector<Eigen::Vector3d> far;
  for (int r = -3; r <= 3; ++r) {
    for (int c = -3; c <= 3; ++c) {
      far.push_back(20 * Eigen::Vector3d(1, std::tan(c * 0.01), std::tan(r * 0.01)));
    }
  }
  const std::vector<Eigen::Isometry3d> poses(2, Eigen::Isometry3d::Identity());
  MovingPointOptions options;
  options.angular_resolution_deg = 0.5;
  EXPECT_EQ(FlagMovingPoints({&near, &far}, poses, {0, 0}, options)[0][0], 1);
  EXPECT_EQ(FlagMovingPoints({&near, &far}, poses, {0, 1}, options)[0][0], 0);
}

}  // namespace
}  // namespace colmap_lidar
