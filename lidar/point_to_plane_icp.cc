#include "lidar/point_to_plane_icp.h"

#include "lidar/util/check_option.h"
#include "lidar/util/parallel_for_each.h"

#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>

namespace colmap_lidar {
namespace {

struct NormalEquations {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  double squared_error = 0;
  double squared_radius = 0;  // sum of |p'|^2: the lever arm of the rotations
  size_t count = 0;
  // Within the gate, with a normal: `count` plus those left out for their target's curvature.
  size_t count_in_gate = 0;

  void Add(const NormalEquations& other) {
    H += other.H;
    g += other.g;
    squared_error += other.squared_error;
    squared_radius += other.squared_radius;
    count += other.count;
    count_in_gate += other.count_in_gate;
  }
};

// Linearised about the current pose: r = n^T (p' - q), d r / d[omega, t] = [p' x n, n]. Target points
// above the curvature bound (with curvatures) count towards the overlap only.
// The clouds of one ICP phase: the source used every `stride`-th point, the target with its tree
// and, for the planar phase, the target's curvature (nullptr: every target point) with its bound.
struct IcpClouds {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree3& tree;
  size_t stride;
  const std::vector<double>* curvature;
  double max_curvature;
};

NormalEquations BuildNormalEquations(const IcpClouds& clouds,
                                     const Eigen::Isometry3d& target_from_source,
                                     double gate) {
  const PointCloud& source = clouds.source;
  const PointCloud& target = clouds.target;
  const size_t stride = clouds.stride;
  const long num = static_cast<long>((source.Size() + stride - 1) / stride);
  return ChunkedSum<NormalEquations>(num, [&](long k, NormalEquations* sum) {
    const Eigen::Vector3d p = target_from_source * source.points[k * stride];
    size_t index;
    double squared;
    if (!clouds.tree.Nearest(p, &index, &squared) || squared > gate * gate) return;
    const Eigen::Vector3d& n = target.normals[index];
    if (n.squaredNorm() < 0.5) return;  // no normal estimated there
    ++sum->count_in_gate;
    if (clouds.curvature && (*clouds.curvature)[index] > clouds.max_curvature) return;
    const double r = n.dot(p - target.points[index]);
    Eigen::Matrix<double, 6, 1> J;
    J << p.cross(n), n;
    sum->H.noalias() += J * J.transpose();
    sum->g.noalias() += J * r;
    sum->squared_error += r * r;
    sum->squared_radius += p.squaredNorm();
    ++sum->count;
  });
}

}  // namespace

Eigen::Isometry3d IsometryFromIncrement(const Eigen::Matrix<double, 6, 1>& x) {
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  const double angle = x.head<3>().norm();
  if (angle > 0) step.linear() = Eigen::AngleAxisd(angle, x.head<3>() / angle).toRotationMatrix();
  step.translation() = x.tail<3>();
  return step;
}

double NextIcpGate(double gate, double residual_rms, double min_gate) {
  return std::max(min_gate, std::min(gate, std::max(0.7 * gate, 6 * residual_rms)));
}

bool IcpOptions::Check() const {
  LIDAR_CHECK_OPTION_GE(max_iterations, 1);
  LIDAR_CHECK_OPTION_GT(min_correspondence_distance, 0);
  LIDAR_CHECK_OPTION_GE(max_correspondence_distance, min_correspondence_distance);
  LIDAR_CHECK_OPTION_GE(max_source_points, 6);
  LIDAR_CHECK_OPTION_GT(max_target_curvature, 0);
  return true;
}

namespace {

enum class IcpRun { kConverged, kStopped, kTooFewCorrespondences };

// Gauss-Newton iterations from *target_from_source until converged or options.max_iterations
// (kStopped), or kTooFewCorrespondences when fewer than 6 remain. *gate and *iterations carry on
// from their values. With curvatures, only the planar target points give residuals and the gate
// stays.
IcpRun IterateIcp(const IcpClouds& clouds,
                  const IcpOptions& options,
                  Eigen::Isometry3d* target_from_source,
                  double* gate,
                  int* iterations) {
  for (int it = 0; it < options.max_iterations; ++it) {
    const NormalEquations eq = BuildNormalEquations(clouds, *target_from_source, *gate);
    ++*iterations;
    if (eq.count < 6) return IcpRun::kTooFewCorrespondences;
    const Eigen::Matrix<double, 6, 1> x = eq.H.ldlt().solve(-eq.g);
    if (!x.allFinite()) return IcpRun::kStopped;
    *target_from_source = IsometryFromIncrement(x) * *target_from_source;
    const bool small_step = x.head<3>().norm() < options.convergence_rotation_rad &&
                            x.tail<3>().norm() < options.convergence_translation_m;
    // With curvatures the gate stays where the first phase left it: the planar residuals' smaller
    // RMS would shrink it, and the overlap (which picks among hypotheses) with it.
    const double next_gate = clouds.curvature ? *gate
                                              : NextIcpGate(*gate,
                                                            std::sqrt(eq.squared_error / eq.count),
                                                            options.min_correspondence_distance);
    // Converged: a small step with the gate settled (at its floor or at a few times the noise).
    if (small_step && next_gate > 0.98 * *gate) return IcpRun::kConverged;
    *gate = next_gate;
  }
  return IcpRun::kStopped;
}

// Throws std::invalid_argument for invalid options or inputs that do not fit together.
void CheckIcpInputs(const PointCloud& source,
                    const PointCloud& target,
                    const KdTree3& target_tree,
                    const IcpOptions& options,
                    const std::vector<double>* target_curvature) {
  ThrowUnlessValid(options, "IcpOptions");
  if (source.Empty() || target.Empty()) throw std::invalid_argument("PointToPlaneIcp: empty cloud");
  if (!target.HasNormals())
    throw std::invalid_argument("PointToPlaneIcp: the target needs normals");
  if (target_tree.Size() != target.Size()) {
    throw std::invalid_argument("PointToPlaneIcp: the k-d tree is not built over the target");
  }
  if (target_curvature && target_curvature->size() != target.Size()) {
    throw std::invalid_argument("PointToPlaneIcp: one curvature per target point expected");
  }
}

}  // namespace

IcpResult PointToPlaneIcp(const PointCloud& source,
                          const PointCloud& target,
                          const KdTree3& target_tree,
                          const Eigen::Isometry3d& initial_target_from_source,
                          const IcpOptions& options,
                          const std::vector<double>* target_curvature) {
  CheckIcpInputs(source, target, target_tree, options, target_curvature);
  const size_t stride = std::max<size_t>(1, source.Size() / options.max_source_points);
  const size_t num_used = (source.Size() + stride - 1) / stride;
  IcpResult result;
  result.target_from_source = initial_target_from_source;
  double gate = options.max_correspondence_distance;
  // Converge on every point first (edges and thin cylinders widen the basin), then, with
  // curvatures, on the planar ones only (their residuals are not biased at the true pose). Too few
  // planar correspondences (a scene of trees and poles): the first phase's result stands.
  const IcpClouds every_point{
      source, target, target_tree, stride, nullptr, options.max_target_curvature};
  result.converged =
      IterateIcp(every_point, options, &result.target_from_source, &gate, &result.iterations) ==
      IcpRun::kConverged;
  const std::vector<double>* used_curvature = nullptr;
  if (result.converged && target_curvature) {
    const Eigen::Isometry3d converged_on_every_point = result.target_from_source;
    const IcpClouds planar_points{
        source, target, target_tree, stride, target_curvature, options.max_target_curvature};
    const IcpRun planar =
        IterateIcp(planar_points, options, &result.target_from_source, &gate, &result.iterations);
    if (planar == IcpRun::kTooFewCorrespondences) {
      result.target_from_source = converged_on_every_point;
    } else {
      used_curvature = target_curvature;
      result.converged = planar == IcpRun::kConverged;
    }
  }
  const IcpClouds final_points{
      source, target, target_tree, stride, used_curvature, options.max_target_curvature};
  const NormalEquations final_eq =
      BuildNormalEquations(final_points, result.target_from_source, gate);
  result.num_inliers = final_eq.count;
  result.overlap_ratio = static_cast<double>(final_eq.count_in_gate) / num_used;
  result.rmse = final_eq.count ? std::sqrt(final_eq.squared_error / final_eq.count) : 0;
  result.hessian = final_eq.H;
  result.lever_arm_m = final_eq.count ? std::sqrt(final_eq.squared_radius / final_eq.count) : 0;
  return result;
}

}  // namespace colmap_lidar
