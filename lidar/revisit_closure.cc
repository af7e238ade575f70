#include "lidar/revisit_closure.h"

#include "lidar/cloud_io.h"
#include "lidar/relative_pose_error.h"
#include "lidar/sweep_pose_graph.h"
#include "lidar/util/check_option.h"

#include <Eigen/Cholesky>

#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

std::vector<double> PathLengths(const std::vector<Eigen::Isometry3d>& world_from_lidar) {
  std::vector<double> path(world_from_lidar.size(), 0.0);
  for (size_t k = 1; k < path.size(); ++k) {
    path[k] = path[k - 1] +
              (world_from_lidar[k].translation() - world_from_lidar[k - 1].translation()).norm();
  }
  return path;
}

// Maps a left increment [omega, t] in the frame of T's source to T's target frame:
// T Exp(d) = Exp(Ad(T) d) T.
Matrix6d Adjoint(const Eigen::Isometry3d& target_from_source) {
  const Eigen::Matrix3d& r = target_from_source.linear();
  const Eigen::Vector3d& p = target_from_source.translation();
  Eigen::Matrix3d p_hat;
  p_hat << 0, -p.z(), p.y(), p.z(), 0, -p.x(), -p.y(), p.x(), 0;
  Matrix6d adjoint = Matrix6d::Zero();
  adjoint.topLeftCorner<3, 3>() = r;
  adjoint.bottomRightCorner<3, 3>() = r;
  adjoint.bottomLeftCorner<3, 3>() = p_hat * r;
  return adjoint;
}

// [2 vec(q_e); t_e] of E = T_pred T_meas^-1 (lidar/relative_pose_error.h, unwhitened).
Vector6d RelativePoseDifference(const Eigen::Isometry3d& world_from_target,
                                const Eigen::Isometry3d& world_from_source,
                                const Eigen::Isometry3d& target_from_source) {
  const RelativePoseError error(target_from_source, Matrix6d::Identity());
  const Eigen::Quaterniond q_i(world_from_target.linear()), q_j(world_from_source.linear());
  const Eigen::Vector3d t_i = world_from_target.translation(),
                        t_j = world_from_source.translation();
  Vector6d residual;
  error(q_i.coeffs().data(), t_i.data(), q_j.coeffs().data(), t_j.data(), residual.data());
  return residual;
}

// The prepared clouds of the candidates' frames, read when first needed and released after their
// last pair.
class CandidateClouds {
 public:
  CandidateClouds(const std::vector<std::string>& cloud_paths,
                  const std::vector<std::pair<size_t, size_t>>& pairs,
                  const StationCloudOptions& options)
      : cloud_paths_(cloud_paths), options_(options) {
    for (size_t p = 0; p < pairs.size(); ++p) {
      last_use_[pairs[p].first] = p;
      last_use_[pairs[p].second] = p;
    }
  }

  const StationCloud& Get(size_t frame) {
    std::unique_ptr<StationCloud>& cloud = clouds_[frame];
    if (!cloud) cloud = PrepareStationCloud(ReadStationCloud(cloud_paths_.at(frame)), options_);
    return *cloud;
  }

  // Releases the clouds whose last pair was `pair_index`.
  void Done(size_t pair_index) {
    for (auto it = clouds_.begin(); it != clouds_.end();) {
      it = last_use_.at(it->first) <= pair_index ? clouds_.erase(it) : std::next(it);
    }
  }

 private:
  const std::vector<std::string>& cloud_paths_;
  const StationCloudOptions& options_;
  std::map<size_t, size_t> last_use_;
  std::map<size_t, std::unique_ptr<StationCloud>> clouds_;
};

// Registers the later keyframe to the earlier one and tests it against the trajectory.
RevisitEdge RegisterRevisit(const StationCloud& earlier,
                            const StationCloud& later,
                            const std::pair<size_t, size_t>& pair,
                            const std::vector<Eigen::Isometry3d>& world_from_lidar,
                            const RevisitOptions& options) {
  RevisitEdge revisit;
  LidarEdge& edge = revisit.edge;
  edge.target = pair.first;
  edge.source = pair.second;
  edge.registration = RegisterStationClouds(later, earlier, options.pair);
  edge.target_from_source = edge.registration.target_from_source;
  if (!edge.registration.accepted) return revisit;
  revisit.chi2 = RevisitChi2(world_from_lidar, edge, options);
  if (revisit.chi2 > options.max_chi2) {
    std::ostringstream reason;
    reason << "chi2 " << revisit.chi2 << " against the odometry's drift exceeds "
           << options.max_chi2;
    edge.registration.accepted = false;
    edge.registration.reason = reason.str();
  }
  return revisit;
}

}  // namespace

bool RevisitOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(keyframe_spacing_m, 0);
  LIDAR_CHECK_OPTION_GT(search_radius_m, 0);
  LIDAR_CHECK_OPTION_GE(min_path_gap_m, 0);
  LIDAR_CHECK_OPTION_GT(max_chi2, 0);
  return drift.Check() && cloud.Check() && pair.Check();
}

std::vector<std::pair<size_t, size_t>> RevisitCandidates(
    const std::vector<Eigen::Isometry3d>& world_from_lidar,
    const RevisitOptions& options,
    size_t* num_keyframes) {
  const std::vector<double> path = PathLengths(world_from_lidar);
  std::vector<size_t> keyframes;
  for (size_t k = 0; k < path.size(); ++k) {
    if (keyframes.empty() || path[k] - path[keyframes.back()] >= options.keyframe_spacing_m) {
      keyframes.push_back(k);
    }
  }
  if (num_keyframes != nullptr) *num_keyframes = keyframes.size();
  std::vector<std::pair<size_t, size_t>> pairs;
  for (const size_t later : keyframes) {
    double nearest = options.search_radius_m;
    std::optional<size_t> match;
    for (size_t earlier = 0; earlier < later; ++earlier) {
      if (path[later] - path[earlier] < options.min_path_gap_m) break;
      const double distance =
          (world_from_lidar[later].translation() - world_from_lidar[earlier].translation()).norm();
      if (distance <= nearest) {
        nearest = distance;
        match = earlier;
      }
    }
    if (match) pairs.emplace_back(*match, later);
  }
  return pairs;
}

Eigen::Matrix<double, 6, 6> DriftCovariance(const std::vector<Eigen::Isometry3d>& world_from_lidar,
                                            size_t target,
                                            size_t source,
                                            const RevisitOptions& options) {
  // A systematic drift u per metre (covariance DriftPerMetre) perturbs step k by s_k u in the frame
  // of k - 1; in the target frame that is Ad(target_from_{k-1}) s_k u, summed along the path.
  Matrix6d jacobian = Matrix6d::Zero();
  Eigen::Isometry3d target_from_previous = Eigen::Isometry3d::Identity();
  for (size_t k = target + 1; k <= source; ++k) {
    const Eigen::Isometry3d step = world_from_lidar[k - 1].inverse() * world_from_lidar[k];
    jacobian += step.translation().norm() * Adjoint(target_from_previous);
    target_from_previous = target_from_previous * step;
  }
  return jacobian * options.drift.PerMetre() * jacobian.transpose();
}

double RevisitChi2(const std::vector<Eigen::Isometry3d>& world_from_lidar,
                   const LidarEdge& edge,
                   const RevisitOptions& options) {
  const Vector6d difference = RelativePoseDifference(
      world_from_lidar.at(edge.target), world_from_lidar.at(edge.source), edge.target_from_source);
  const Matrix6d covariance = DriftCovariance(world_from_lidar, edge.target, edge.source, options) +
                              RegistrationCovariance(edge.registration);
  return difference.dot(covariance.ldlt().solve(difference));
}

RevisitClosure CloseRevisits(const std::vector<std::string>& cloud_paths,
                             const RevisitOptions& options,
                             LidarGraph* graph,
                             const std::function<void(size_t, size_t)>& progress) {
  if (!options.Check()) throw std::invalid_argument("CloseRevisits: invalid options");
  if (cloud_paths.size() != graph->world_from_lidar.size()) {
    throw std::invalid_argument("CloseRevisits: one cloud per pose is needed");
  }
  const auto start = std::chrono::steady_clock::now();
  RevisitClosure closure;
  const std::vector<std::pair<size_t, size_t>> pairs =
      RevisitCandidates(graph->world_from_lidar, options, &closure.num_keyframes);
  closure.num_candidates = pairs.size();
  CandidateClouds clouds(cloud_paths, pairs, options.cloud);
  for (size_t p = 0; p < pairs.size(); ++p) {
    const StationCloud& earlier = clouds.Get(pairs[p].first);
    const StationCloud& later = clouds.Get(pairs[p].second);
    RevisitEdge revisit =
        RegisterRevisit(earlier, later, pairs[p], graph->world_from_lidar, options);
    clouds.Done(p);
    if (revisit.edge.registration.accepted) {
      closure.accepted.push_back(std::move(revisit));
    } else {
      graph->refused.push_back(revisit.edge);
      closure.refused.push_back(std::move(revisit));
    }
    if (progress) progress(p + 1, pairs.size());
  }
  if (!closure.accepted.empty()) {
    for (const RevisitEdge& revisit : closure.accepted) graph->edges.push_back(revisit.edge);
    SolveSweepPoseGraph(options.drift, graph);
  }
  closure.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return closure;
}

}  // namespace colmap_lidar
