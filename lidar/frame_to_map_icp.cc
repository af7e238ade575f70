#include "lidar/frame_to_map_icp.h"

#include "lidar/util/check_option.h"
#include "lidar/util/parallel_for_each.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

struct NormalSystem {
  Matrix6d hessian = Matrix6d::Zero();
  Vector6d gradient = Vector6d::Zero();
  size_t count = 0;
  double sum_squares = 0;

  void Add(const NormalSystem& other) {
    hessian += other.hessian;
    gradient += other.gradient;
    count += other.count;
    sum_squares += other.sum_squares;
  }
};

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// One residual's contribution: point-to-plane where the map is a plane, point-to-point where it is
// scattered; none on a line (one scan line's arc: across it lies the scanner's ring pattern) or
// where the map is too sparse to tell (its points there follow the scanner's pattern too).
void AddResidual(const Eigen::Vector3d& x,
                 const MapNeighbor& neighbor,
                 double kernel,
                 bool point_to_plane,
                 NormalSystem* system) {
  if (point_to_plane &&
      (neighbor.shape == VoxelShape::kLine || neighbor.shape == VoxelShape::kSparse)) {
    return;
  }
  Eigen::Matrix<double, 3, 6> jacobian;
  jacobian << -Skew(x), Eigen::Matrix3d::Identity();
  if (point_to_plane && neighbor.shape == VoxelShape::kPlane) {
    const double r = neighbor.normal.dot(x - neighbor.point);
    const Vector6d j = jacobian.transpose() * neighbor.normal;
    const double w = kernel * kernel / std::pow(kernel + r * r, 2);
    system->hessian.noalias() += w * j * j.transpose();
    system->gradient.noalias() += w * r * j;
    system->sum_squares += r * r;
  } else {
    const Eigen::Vector3d r = x - neighbor.point;
    const double w = kernel * kernel / std::pow(kernel + r.squaredNorm(), 2);
    system->hessian.noalias() += w * jacobian.transpose() * jacobian;
    system->gradient.noalias() += w * jacobian.transpose() * r;
    system->sum_squares += r.squaredNorm();
  }
  ++system->count;
}

// The nearest map point of pose * p for each point p within max_distance (index -1: none), with
// the shape of the map around it when `neighbourhood_shape`
// (VoxelHashMap::ClassifyNeighbourhoods), else that of its voxel.
std::vector<MapNeighbor> FindCorrespondences(const std::vector<Eigen::Vector3d>& points,
                                             VoxelHashMap* map,
                                             const Eigen::Isometry3d& pose,
                                             double max_distance,
                                             bool neighbourhood_shape) {
  std::vector<MapNeighbor> neighbors(points.size());
  // Each item writes its own slot and cannot throw: a plain static loop (ParallelForEach's
  // per-item scheduling costs as much as a search).
#pragma omp parallel for schedule(static)
  for (long i = 0; i < static_cast<long>(points.size()); ++i) {
    MapNeighbor& neighbor = neighbors[i];
    if (!map->NearestNeighbor(pose * points[i], &neighbor) || neighbor.distance > max_distance) {
      neighbor.index = -1;
    }
  }
  if (neighbourhood_shape) map->ClassifyNeighbourhoods(&neighbors);
  return neighbors;
}

// The sum over the points' correspondences (FindCorrespondences) of
// `add(i, x, neighbor, system)`, x = pose * points[i], in fixed chunks combined in order.
template <typename Add>
NormalSystem SumOverCorrespondences(const std::vector<Eigen::Vector3d>& points,
                                    VoxelHashMap* map,
                                    const Eigen::Isometry3d& pose,
                                    double max_distance,
                                    bool neighbourhood_shape,
                                    const Add& add) {
  const std::vector<MapNeighbor> neighbors =
      FindCorrespondences(points, map, pose, max_distance, neighbourhood_shape);
  return ChunkedSum<NormalSystem>(static_cast<long>(points.size()), [&](long i, NormalSystem* sum) {
    if (neighbors[i].index >= 0) add(i, pose * points[i], neighbors[i], sum);
  });
}

// One Gauss-Newton system of the residuals at `pose` (Eq. 7-8).
NormalSystem IcpSystem(const std::vector<Eigen::Vector3d>& points,
                       VoxelHashMap* map,
                       const Eigen::Isometry3d& pose,
                       double max_distance,
                       double kernel,
                       bool point_to_plane) {
  return SumOverCorrespondences(
      points,
      map,
      pose,
      max_distance,
      point_to_plane,
      [&](int, const Eigen::Vector3d& x, const MapNeighbor& neighbor, NormalSystem* system) {
        AddResidual(x, neighbor, kernel, point_to_plane, system);
      });
}

Eigen::Isometry3d Increment(const Vector6d& dx) {
  Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();
  const double angle = dx.head<3>().norm();
  if (angle > 0) {
    increment.linear() = Eigen::AngleAxisd(angle, dx.head<3>() / angle).toRotationMatrix();
  }
  increment.translation() = dx.tail<3>();
  return increment;
}

// Point-to-plane information of the converged pose in the LiDAR frame (right increment).
void PlaneInformation(const std::vector<Eigen::Vector3d>& points,
                      VoxelHashMap* map,
                      double max_distance,
                      double kernel,
                      FrameToMapIcpResult* result) {
  const Eigen::Isometry3d& pose = result->world_from_lidar;
  const NormalSystem total = SumOverCorrespondences(
      points,
      map,
      pose,
      max_distance,
      true,
      [&](int i, const Eigen::Vector3d& x, const MapNeighbor& neighbor, NormalSystem* system) {
        if (neighbor.shape != VoxelShape::kPlane) return;
        const double r = neighbor.normal.dot(x - neighbor.point);
        const Eigen::Vector3d m = pose.linear().transpose() * neighbor.normal;
        Vector6d jacobian;
        jacobian << points[i].cross(m), m;
        const double w = kernel * kernel / std::pow(kernel + r * r, 2);
        system->hessian.noalias() += w * jacobian * jacobian.transpose();
        system->sum_squares += r * r;
        ++system->count;
      });
  result->information = total.hessian;
  result->num_plane_correspondences = total.count;
  result->plane_rms_m = total.count ? std::sqrt(total.sum_squares / total.count) : 0.0;
}

}  // namespace

bool FrameToMapIcpOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(max_iterations, 0);
  LIDAR_CHECK_OPTION_GT(convergence, 0);
  return true;
}

FrameToMapIcpResult AlignFrameToMap(const std::vector<Eigen::Vector3d>& points_in_lidar,
                                    VoxelHashMap* map,
                                    const Eigen::Isometry3d& initial,
                                    double max_correspondence_m,
                                    double kernel_m,
                                    const FrameToMapIcpOptions& options) {
  ThrowUnlessValid(options, "FrameToMapIcpOptions");
  if (!(max_correspondence_m > 0) || !(kernel_m > 0)) {
    throw std::invalid_argument("AlignFrameToMap: threshold and kernel must be > 0");
  }
  FrameToMapIcpResult result;
  result.world_from_lidar = initial;
  for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
    const NormalSystem system = IcpSystem(points_in_lidar,
                                          map,
                                          result.world_from_lidar,
                                          max_correspondence_m,
                                          kernel_m,
                                          options.point_to_plane);
    result.num_iterations = iteration;
    result.num_correspondences = system.count;
    result.rms_m = system.count ? std::sqrt(system.sum_squares / system.count) : 0.0;
    if (system.count < 6) break;
    const Vector6d dx = system.hessian.ldlt().solve(-system.gradient);
    if (!dx.allFinite()) break;
    result.world_from_lidar = Increment(dx) * result.world_from_lidar;
    if (dx.norm() < options.convergence) {
      result.converged = true;
      break;
    }
  }
  PlaneInformation(points_in_lidar, map, max_correspondence_m, kernel_m, &result);
  return result;
}

}  // namespace colmap_lidar
