#include "lidar/frame_to_map_icp.h"

#include "lidar/check_option.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// Fixed chunks: the sums do not depend on the thread count.
constexpr int kNumChunks = 64;

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

// One Gauss-Newton system of the point-to-point residuals at `pose` (Eq. 7-8).
NormalSystem PointToPointSystem(const std::vector<Eigen::Vector3d>& points,
                                const VoxelHashMap& map,
                                const Eigen::Isometry3d& pose,
                                double max_distance,
                                double kernel) {
  std::vector<NormalSystem> chunks(kNumChunks);
  const int n = static_cast<int>(points.size());
#pragma omp parallel for schedule(static)
  for (int c = 0; c < kNumChunks; ++c) {
    NormalSystem& system = chunks[c];
    for (int i = c * n / kNumChunks; i < (c + 1) * n / kNumChunks; ++i) {
      const Eigen::Vector3d x = pose * points[i];
      Eigen::Vector3d q;
      double distance = 0;
      if (!map.NearestNeighbor(x, &q, &distance) || distance > max_distance) continue;
      const Eigen::Vector3d r = x - q;
      Eigen::Matrix<double, 3, 6> jacobian;
      jacobian << -Skew(x), Eigen::Matrix3d::Identity();
      const double w = kernel * kernel / std::pow(kernel + r.squaredNorm(), 2);
      system.hessian.noalias() += w * jacobian.transpose() * jacobian;
      system.gradient.noalias() += w * jacobian.transpose() * r;
      system.sum_squares += r.squaredNorm();
      ++system.count;
    }
  }
  NormalSystem total;
  for (const NormalSystem& chunk : chunks) total.Add(chunk);
  return total;
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

// The normal of the map's points within `radius` of q (PCA), or
// false where they do not form a plane.
bool MapNormal(const VoxelHashMap& map,
               const Eigen::Vector3d& q,
               double radius,
               Eigen::Vector3d* normal) {
  const std::vector<Eigen::Vector3d> near = map.PointsNear(q, radius);
  if (near.size() < 5) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : near) mean += p / static_cast<double>(near.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : near) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  // A plane: thin (spread across it below 0.3 of the smaller spread within it) and two-dimensional
  // (not the arc of one scan line, whose normal would be any direction across the line).
  const Eigen::Vector3d& variances = solver.eigenvalues();
  if (!(variances(0) < 0.1 * variances(1)) || !(variances(1) > 0.04 * variances(2))) return false;
  *normal = solver.eigenvectors().col(0);
  return true;
}

// Point-to-plane information of the converged pose in the LiDAR frame (right increment).
void PlaneInformation(const std::vector<Eigen::Vector3d>& points,
                      const VoxelHashMap& map,
                      double max_distance,
                      double kernel,
                      FrameToMapIcpResult* result) {
  const Eigen::Isometry3d& pose = result->world_from_lidar;
  std::vector<NormalSystem> chunks(kNumChunks);
  const int n = static_cast<int>(points.size());
#pragma omp parallel for schedule(static)
  for (int c = 0; c < kNumChunks; ++c) {
    for (int i = c * n / kNumChunks; i < (c + 1) * n / kNumChunks; ++i) {
      const Eigen::Vector3d x = pose * points[i];
      Eigen::Vector3d q, normal;
      double distance = 0;
      if (!map.NearestNeighbor(x, &q, &distance) || distance > max_distance) continue;
      if (!MapNormal(map, q, map.VoxelSize(), &normal)) continue;
      const double r = normal.dot(x - q);
      const Eigen::Vector3d m = pose.linear().transpose() * normal;
      Vector6d jacobian;
      jacobian << points[i].cross(m), m;
      const double w = kernel * kernel / std::pow(kernel + r * r, 2);
      chunks[c].hessian.noalias() += w * jacobian * jacobian.transpose();
      chunks[c].sum_squares += r * r;
      ++chunks[c].count;
    }
  }
  NormalSystem total;
  for (const NormalSystem& chunk : chunks) total.Add(chunk);
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
                                    const VoxelHashMap& map,
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
    const NormalSystem system = PointToPointSystem(
        points_in_lidar, map, result.world_from_lidar, max_correspondence_m, kernel_m);
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
