#include "lidar/pair_registration.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>
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

}  // namespace

bool PairRegistrationOptions::Check() const {
  if (!(max_ratio > 0) || ransac_iterations < 1 || !(inlier_threshold > 0) ||
      !(edge_tolerance > 0) || min_inliers < 3 || num_hypotheses < 1 || !(min_overlap >= 0) ||
      !(max_rmse > 0)) {
    throw std::invalid_argument("PairRegistrationOptions: invalid value");
  }
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
  options.Check();
  PairRegistration result;
  const auto matches =
      MatchBscFeatures(source.features, target.features, options.max_ratio, options.mutual);
  result.num_matches = matches.size();
  if (static_cast<int>(matches.size()) < options.min_inliers) {
    result.reason = "too few BSC matches (" + std::to_string(matches.size()) + ")";
    return result;
  }
  const size_t n = matches.size();
  Eigen::Matrix3Xd source_points(3, n), target_points(3, n);
  for (size_t k = 0; k < n; ++k) {
    source_points.col(k) = source.features[matches[k].first].position;
    target_points.col(k) = target.features[matches[k].second].position;
  }
  auto inliers_of = [&](const Eigen::Isometry3d& t, std::vector<size_t>* inliers) {
    inliers->clear();
    for (size_t k = 0; k < n; ++k) {
      if ((t * source_points.col(k) - target_points.col(k)).norm() < options.inlier_threshold) {
        inliers->push_back(k);
      }
    }
  };
  // RANSAC keeps the best few *distinct* hypotheses: repetitive structure (parallel walls, symmetric
  // rooms) gives several strong ones, and ICP's overlap decides between them.
  struct Hypothesis {
    Eigen::Isometry3d target_from_source;
    std::vector<size_t> inliers;
  };
  std::vector<Hypothesis> hypotheses;
  auto distinct = [](const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    const Eigen::Isometry3d d = a * b.inverse();
    return Eigen::AngleAxisd(d.linear()).angle() > 5 * M_PI / 180 || d.translation().norm() > 0.5;
  };
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  std::vector<size_t> inliers;
  // A fixed budget, no adaptive termination: a strong wrong hypothesis (repetitive structure) would
  // stop the search before the right one is drawn. Samples failing the edge check cost nanoseconds.
  for (int it = 0; it < options.ransac_iterations; ++it) {
    const size_t a = pick(rng), b = pick(rng), c = pick(rng);
    if (a == b || b == c || a == c) continue;
    // Edge-length consistency: a rigid motion preserves the triangle.
    bool consistent = true;
    for (const auto& [i, j] : {std::pair{a, b}, std::pair{b, c}, std::pair{a, c}}) {
      const double ds = (source_points.col(i) - source_points.col(j)).norm();
      const double dt = (target_points.col(i) - target_points.col(j)).norm();
      if (std::abs(ds - dt) > options.edge_tolerance || ds < 2 * options.inlier_threshold) {
        consistent = false;
      }
    }
    if (!consistent) continue;
    Eigen::Matrix3Xd s(3, 3), t(3, 3);
    s << source_points.col(a), source_points.col(b), source_points.col(c);
    t << target_points.col(a), target_points.col(b), target_points.col(c);
    const Eigen::Isometry3d candidate = Kabsch(s, t);
    inliers_of(candidate, &inliers);
    if (static_cast<int>(inliers.size()) < options.min_inliers) continue;
    bool merged = false;
    for (Hypothesis& h : hypotheses) {
      if (!distinct(h.target_from_source, candidate)) {
        if (inliers.size() > h.inliers.size()) h = {candidate, inliers};
        merged = true;
        break;
      }
    }
    if (!merged) hypotheses.push_back({candidate, inliers});
    std::sort(hypotheses.begin(), hypotheses.end(), [](const Hypothesis& x, const Hypothesis& y) {
      return x.inliers.size() > y.inliers.size();
    });
    if (static_cast<int>(hypotheses.size()) > options.num_hypotheses) hypotheses.pop_back();
  }
  if (hypotheses.empty()) {
    result.reason = "too few RANSAC inliers (fewer than " + std::to_string(options.min_inliers) +
                    " of " + std::to_string(n) + " matches)";
    return result;
  }
  bool have_candidate = false;
  for (Hypothesis& h : hypotheses) {
    // Refit on all inliers (twice: the refit may gain inliers), then ICP.
    for (int refit = 0; refit < 2; ++refit) {
      Eigen::Matrix3Xd s(3, h.inliers.size()), t(3, h.inliers.size());
      for (size_t k = 0; k < h.inliers.size(); ++k) {
        s.col(k) = source_points.col(h.inliers[k]);
        t.col(k) = target_points.col(h.inliers[k]);
      }
      const Eigen::Isometry3d refit_pose = Kabsch(s, t);
      inliers_of(refit_pose, &inliers);
      if (inliers.size() < h.inliers.size()) break;
      h = {refit_pose, inliers};
    }
    const IcpResult fine = PointToPlaneIcp(
        source.cloud, target.cloud, *target.tree, h.target_from_source, options.icp);
    if (!have_candidate || fine.overlap_ratio > result.overlap) {
      have_candidate = true;
      result.target_from_source = fine.target_from_source;
      result.num_inliers = h.inliers.size();
      result.overlap = fine.overlap_ratio;
      result.rmse = fine.rmse;
      result.converged = fine.converged;
    }
  }
  if (!result.converged) {
    result.reason = "ICP did not converge";
  } else if (result.overlap < options.min_overlap) {
    result.reason = "overlap " + std::to_string(result.overlap) + " below " +
                    std::to_string(options.min_overlap);
  } else if (result.rmse > options.max_rmse) {
    result.reason =
        "ICP RMSE " + std::to_string(result.rmse) + " m above " + std::to_string(options.max_rmse);
  } else {
    result.accepted = true;
  }
  return result;
}

}  // namespace colmap_lidar
