#include "lidar/pair_registration.h"

#include "lidar/util/check_option.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

Eigen::Isometry3d Kabsch(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target) {
  Eigen::Isometry3d result;
  result.matrix() = Eigen::umeyama(source, target, /*with_scaling=*/false);
  return result;
}

struct Nearest {
  size_t index = 0;
  int best = 1 << 30;
  int second = 1 << 30;
};

std::vector<Nearest> NearestInHamming(const std::vector<BscFeature>& from,
                                      const std::vector<BscFeature>& to) {
  std::vector<Nearest> nearest(from.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (size_t i = 0; i < from.size(); ++i) {
    for (size_t j = 0; j < to.size(); ++j) {
      const int d = BscDistance(from[i], to[j]);
      if (d < nearest[i].best) {
        nearest[i].second = nearest[i].best;
        nearest[i].best = d;
        nearest[i].index = j;
      } else if (d < nearest[i].second) {
        nearest[i].second = d;
      }
    }
  }
  return nearest;
}

// RANSAC keeps the best few *distinct* hypotheses: repetitive structure (parallel walls, symmetric
// rooms) gives several strong ones, and ICP's overlap decides between them.
struct Hypothesis {
  Eigen::Isometry3d target_from_source;
  std::vector<size_t> inliers;
};

class RansacOnMatches {
 public:
  RansacOnMatches(const Eigen::Matrix3Xd& source_points,
                  const Eigen::Matrix3Xd& target_points,
                  const PairRegistrationOptions& options)
      : source_(source_points), target_(target_points), options_(options) {}

  void Inliers(const Eigen::Isometry3d& t, std::vector<size_t>* inliers) const {
    inliers->clear();
    for (long k = 0; k < source_.cols(); ++k) {
      if ((t * source_.col(k) - target_.col(k)).norm() < options_.inlier_threshold) {
        inliers->push_back(k);
      }
    }
  }

  // A fixed budget, no adaptive termination: a strong wrong hypothesis (repetitive structure) would
  // stop the search before the right one is drawn. Samples failing the edge check cost nanoseconds.
  std::vector<Hypothesis> Run() const {
    std::vector<Hypothesis> hypotheses;
    std::mt19937_64 rng(options_.seed);
    std::uniform_int_distribution<size_t> pick(0, source_.cols() - 1);
    std::vector<size_t> inliers;
    for (int it = 0; it < options_.ransac_iterations; ++it) {
      const size_t a = pick(rng), b = pick(rng), c = pick(rng);
      if (a == b || b == c || a == c || !RigidTriangle(a, b, c)) continue;
      Eigen::Matrix3Xd s(3, 3), t(3, 3);
      s << source_.col(a), source_.col(b), source_.col(c);
      t << target_.col(a), target_.col(b), target_.col(c);
      const Eigen::Isometry3d candidate = Kabsch(s, t);
      Inliers(candidate, &inliers);
      if (static_cast<int>(inliers.size()) < options_.min_inliers) continue;
      Insert({candidate, inliers}, &hypotheses);
    }
    for (Hypothesis& h : hypotheses) Refit(&h);
    return hypotheses;
  }

 private:
  // Edge-length consistency: a rigid motion preserves the triangle.
  bool RigidTriangle(size_t a, size_t b, size_t c) const {
    for (const auto& [i, j] : {std::pair{a, b}, std::pair{b, c}, std::pair{a, c}}) {
      const double ds = (source_.col(i) - source_.col(j)).norm();
      const double dt = (target_.col(i) - target_.col(j)).norm();
      if (std::abs(ds - dt) > options_.edge_tolerance || ds < 2 * options_.inlier_threshold) {
        return false;
      }
    }
    return true;
  }

  void Insert(Hypothesis candidate, std::vector<Hypothesis>* hypotheses) const {
    const auto distinct = [](const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
      const Eigen::Isometry3d d = a * b.inverse();
      return Eigen::AngleAxisd(d.linear()).angle() > 5 * M_PI / 180 || d.translation().norm() > 0.5;
    };
    bool merged = false;
    for (Hypothesis& h : *hypotheses) {
      if (!distinct(h.target_from_source, candidate.target_from_source)) {
        if (candidate.inliers.size() > h.inliers.size()) h = std::move(candidate);
        merged = true;
        break;
      }
    }
    if (!merged) hypotheses->push_back(std::move(candidate));
    std::sort(hypotheses->begin(), hypotheses->end(), [](const Hypothesis& x, const Hypothesis& y) {
      return x.inliers.size() > y.inliers.size();
    });
    if (static_cast<int>(hypotheses->size()) > options_.num_hypotheses) hypotheses->pop_back();
  }

  // Refit on all inliers (twice: the refit may gain inliers).
  void Refit(Hypothesis* h) const {
    std::vector<size_t> inliers;
    for (int refit = 0; refit < 2; ++refit) {
      Eigen::Matrix3Xd s(3, h->inliers.size()), t(3, h->inliers.size());
      for (size_t k = 0; k < h->inliers.size(); ++k) {
        s.col(k) = source_.col(h->inliers[k]);
        t.col(k) = target_.col(h->inliers[k]);
      }
      const Eigen::Isometry3d refit_pose = Kabsch(s, t);
      Inliers(refit_pose, &inliers);
      if (inliers.size() < h->inliers.size()) break;
      *h = {refit_pose, inliers};
    }
  }

  const Eigen::Matrix3Xd& source_;
  const Eigen::Matrix3Xd& target_;
  const PairRegistrationOptions& options_;
};

std::vector<Hypothesis> BscHypotheses(const StationCloud& source,
                                      const StationCloud& target,
                                      const PairRegistrationOptions& options,
                                      Eigen::Matrix3Xd* source_points,
                                      Eigen::Matrix3Xd* target_points,
                                      PairRegistration* result) {
  const auto matches =
      MatchBscFeatures(source.features, target.features, options.max_ratio, options.mutual);
  result->num_matches = matches.size();
  if (static_cast<int>(matches.size()) < options.min_inliers) {
    result->reason = "too few BSC matches (" + std::to_string(matches.size()) + ")";
    return {};
  }
  source_points->resize(3, matches.size());
  target_points->resize(3, matches.size());
  for (size_t k = 0; k < matches.size(); ++k) {
    source_points->col(k) = source.features[matches[k].first].position;
    target_points->col(k) = target.features[matches[k].second].position;
  }
  std::vector<Hypothesis> hypotheses =
      RansacOnMatches(*source_points, *target_points, options).Run();
  if (hypotheses.empty()) {
    result->reason = "too few RANSAC inliers (fewer than " + std::to_string(options.min_inliers) +
                     " of " + std::to_string(matches.size()) + " matches)";
  }
  return hypotheses;
}

// The alignment, fit and constraint analysis of a final ICP.
void TakeIcpResult(const IcpResult& icp, PairRegistration* result) {
  result->target_from_source = icp.target_from_source;
  result->overlap = icp.overlap_ratio;
  result->rmse = icp.rmse;
  result->converged = icp.converged;
  result->hessian = icp.hessian;
  result->constraints =
      icp.lever_arm_m > 0 ? AnalyseConstraints(icp.hessian, icp.lever_arm_m) : ConstraintAnalysis();
}

// The pair's expected ICP RMSE from the clouds' own plane noise [m].
double PairNoiseRms(const StationCloud& source, const StationCloud& target) {
  return std::sqrt(0.5 * (source.plane_noise_rms * source.plane_noise_rms +
                          target.plane_noise_rms * target.plane_noise_rms));
}

// The gates, in order; the first that fails names the reason.
void Judge(const PairRegistrationOptions& options, PairRegistration* result) {
  std::ostringstream reason;
  const double rmse_to_noise = result->rmse / std::max(result->noise_rms, 1e-9);
  if (!result->converged) {
    reason << "ICP did not converge";
  } else if (result->overlap < options.min_overlap) {
    reason << "overlap " << result->overlap << " below " << options.min_overlap;
  } else if (rmse_to_noise > options.max_rmse_to_noise) {
    reason << "ICP RMSE " << result->rmse << " m is " << rmse_to_noise
           << " x the clouds' plane noise " << result->noise_rms << " m (max "
           << options.max_rmse_to_noise << ")";
  } else if (options.max_rmse > 0 && result->rmse > options.max_rmse) {
    reason << "ICP RMSE " << result->rmse << " m above " << options.max_rmse;
  } else if (result->constraints.weakest_ratio < options.min_constraint_ratio) {
    reason << "degenerate: direction " << result->constraints.WeakestAxisName()
           << " unconstrained (constraint ratio " << result->constraints.weakest_ratio << ")";
  }
  result->reason = reason.str();
  result->accepted = result->reason.empty();
  result->degenerate =
      result->accepted && result->constraints.weakest_ratio < options.weak_constraint_ratio;
}

// Coarse ICP from every hypothesis on a subset of the source; the `num_refined` with the best overlap
// are kept, starting from their coarse alignment (the full-resolution ICP refines them).
void ScreenHypotheses(const StationCloud& source,
                      const StationCloud& target,
                      const PairRegistrationOptions& options,
                      std::vector<Hypothesis>* hypotheses) {
  if (options.screening_source_points == 0 ||
      hypotheses->size() <= static_cast<size_t>(options.num_refined)) {
    return;
  }
  IcpOptions coarse = options.icp;
  coarse.max_source_points = std::min(coarse.max_source_points, options.screening_source_points);
  std::vector<std::pair<double, size_t>> overlaps;
  for (size_t k = 0; k < hypotheses->size(); ++k) {
    Hypothesis& h = (*hypotheses)[k];
    // Every target point (no curvature filter): screening only ranks the basins.
    const IcpResult result =
        PointToPlaneIcp(source.cloud, target.cloud, *target.tree, h.target_from_source, coarse);
    h.target_from_source = result.target_from_source;
    overlaps.emplace_back(-result.overlap_ratio, k);  // best first; ties keep the order
  }
  std::stable_sort(overlaps.begin(), overlaps.end());
  std::vector<Hypothesis> kept;
  for (int k = 0; k < options.num_refined; ++k) kept.push_back((*hypotheses)[overlaps[k].second]);
  *hypotheses = std::move(kept);
}

}  // namespace

bool PairRegistrationOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(max_ratio, 0);
  LIDAR_CHECK_OPTION_GE(ransac_iterations, 1);
  LIDAR_CHECK_OPTION_GT(inlier_threshold, 0);
  LIDAR_CHECK_OPTION_GT(edge_tolerance, 0);
  LIDAR_CHECK_OPTION_GE(min_inliers, 3);
  LIDAR_CHECK_OPTION_GE(num_hypotheses, 1);
  LIDAR_CHECK_OPTION_GE(min_overlap, 0);
  LIDAR_CHECK_OPTION_GT(max_rmse_to_noise, 0);
  LIDAR_CHECK_OPTION_GE(max_rmse, 0);
  LIDAR_CHECK_OPTION_GE(min_constraint_ratio, 0);
  LIDAR_CHECK_OPTION_GE(weak_constraint_ratio, min_constraint_ratio);
  LIDAR_CHECK_OPTION(screening_source_points == 0 || screening_source_points >= 6);
  LIDAR_CHECK_OPTION_GE(num_refined, 1);
  return icp.Check();
}

std::vector<std::pair<size_t, size_t>> MatchBscFeatures(const std::vector<BscFeature>& source,
                                                        const std::vector<BscFeature>& target,
                                                        double max_ratio,
                                                        bool mutual) {
  std::vector<std::pair<size_t, size_t>> matches;
  if (source.empty() || target.empty()) return matches;
  const std::vector<Nearest> forward = NearestInHamming(source, target);
  std::vector<Nearest> backward;
  if (mutual) backward = NearestInHamming(target, source);
  for (size_t i = 0; i < source.size(); ++i) {
    const Nearest& n = forward[i];
    if (n.best > max_ratio * n.second) continue;
    if (mutual && backward[n.index].index != i) continue;
    matches.emplace_back(i, n.index);
  }
  return matches;
}

PairRegistration RegisterStationClouds(const StationCloud& source,
                                       const StationCloud& target,
                                       const PairRegistrationOptions& options) {
  ThrowUnlessValid(options, "PairRegistrationOptions");
  PairRegistration result;
  Eigen::Matrix3Xd source_points, target_points;
  std::vector<Hypothesis> hypotheses =
      BscHypotheses(source, target, options, &source_points, &target_points, &result);
  const std::string bsc_reason = result.reason;
  if (options.try_identity) hypotheses.push_back({Eigen::Isometry3d::Identity(), {}});
  if (hypotheses.empty()) return result;
  ScreenHypotheses(source, target, options, &hypotheses);
  bool have_candidate = false;
  for (const Hypothesis& h : hypotheses) {
    const IcpResult fine = PointToPlaneIcp(source.cloud,
                                           target.cloud,
                                           *target.tree,
                                           h.target_from_source,
                                           options.icp,
                                           &target.curvature);
    if (have_candidate && fine.overlap_ratio <= result.overlap) continue;
    have_candidate = true;
    TakeIcpResult(fine, &result);
    result.num_inliers = h.inliers.size();
    result.from_identity = h.inliers.empty();
  }
  if (result.from_identity) {
    // The BSC matches that agree with the alignment ICP found from the identity.
    std::vector<size_t> agreeing;
    RansacOnMatches(source_points, target_points, options)
        .Inliers(result.target_from_source, &agreeing);
    result.num_inliers = agreeing.size();
  }
  result.noise_rms = PairNoiseRms(source, target);
  Judge(options, &result);
  if (!result.accepted && result.from_identity && !bsc_reason.empty()) {
    result.reason = bsc_reason + "; from the identity: " + result.reason;
  }
  return result;
}

PairRegistration RegisterFromGuess(const StationCloud& source,
                                   const StationCloud& target,
                                   const Eigen::Isometry3d& target_from_source_guess,
                                   const PairRegistrationOptions& options) {
  ThrowUnlessValid(options, "PairRegistrationOptions");
  PairRegistration result;
  TakeIcpResult(PointToPlaneIcp(source.cloud,
                                target.cloud,
                                *target.tree,
                                target_from_source_guess,
                                options.icp,
                                &target.curvature),
                &result);
  result.noise_rms = PairNoiseRms(source, target);
  Judge(options, &result);
  return result;
}

}  // namespace colmap_lidar
