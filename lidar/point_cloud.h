// An Eigen-only point cloud: positions, optional normals, colours, intensities and per-point times
// (each either empty or of the same length as `points`). Positions are in the frame the producer
// names (e.g. point_in_lidar).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace colmap_lidar {

using Color3ub = Eigen::Matrix<uint8_t, 3, 1>;

struct PointCloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
  std::vector<Color3ub> colors;
  std::vector<float> intensities;
  // When each point was measured, as the file's time field gives it (any unit and origin: a driver's
  // seconds or nanoseconds, from the sweep's start or absolute); lidar/sweep_deskew.h times a sweep
  // by it.
  std::vector<double> times;

  size_t Size() const { return points.size(); }
  bool Empty() const { return points.empty(); }
  bool HasNormals() const { return !normals.empty(); }
  bool HasColors() const { return !colors.empty(); }
  bool HasIntensities() const { return !intensities.empty(); }
  bool HasTimes() const { return !times.empty(); }

  // Throws std::invalid_argument when an attribute has neither 0 nor Size() entries.
  void CheckConsistent() const;
  void Reserve(size_t n, bool normals, bool colors, bool intensities);
};

}  // namespace colmap_lidar
