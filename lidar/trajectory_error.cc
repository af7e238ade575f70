#include "lidar/trajectory_error.h"

#include "lidar/util/check_option.h"
#include "lidar/util/statistics.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace colmap_lidar {

namespace {

using Poses = std::vector<Eigen::Isometry3d>;

constexpr double kDefaultLengthStepM = 10;
constexpr double kDefaultMaxLengthM = 800;

// E = A^-1 B of the estimate's and the reference's motions from frame i to frame j.
Eigen::Isometry3d RelativeError(const Poses& estimate, const Poses& reference, size_t i, size_t j) {
  const Eigen::Isometry3d a = estimate[i].inverse() * estimate[j];
  const Eigen::Isometry3d b = reference[i].inverse() * reference[j];
  return a.inverse() * b;
}

// Path length along the reference up to each frame.
std::vector<double> Distances(const Poses& reference) {
  std::vector<double> distances(reference.size(), 0.0);
  for (size_t k = 1; k < reference.size(); ++k) {
    distances[k] =
        distances[k - 1] + (reference[k].translation() - reference[k - 1].translation()).norm();
  }
  return distances;
}

std::vector<double> SegmentLengths(const TrajectoryErrorOptions& options, double path_length) {
  if (!options.lengths_m.empty()) return options.lengths_m;
  std::vector<double> lengths;
  for (double length = kDefaultLengthStepM;
       length <= std::min(path_length, kDefaultMaxLengthM) + 1e-9;
       length += kDefaultLengthStepM) {
    lengths.push_back(length);
  }
  return lengths;
}

// KITTI's relative errors per length and over all (i, L) samples.
void RelativeErrors(const Poses& estimate,
                    const Poses& reference,
                    const std::vector<double>& distances,
                    const std::vector<double>& lengths,
                    TrajectoryError* result) {
  double translation_sum = 0, rotation_sum = 0;
  for (const double length : lengths) {
    SegmentLengthError segment;
    segment.length_m = length;
    double t_sum = 0, r_sum = 0;
    for (size_t i = 0; i < reference.size(); ++i) {
      const auto end =
          std::lower_bound(distances.begin() + i, distances.end(), distances[i] + length);
      if (end == distances.end()) break;
      const Eigen::Isometry3d error =
          RelativeError(estimate, reference, i, end - distances.begin());
      t_sum += error.translation().norm() / length;
      r_sum += RotationAngleDeg(error.linear()) / length;
      ++segment.count;
    }
    if (segment.count > 0) {
      segment.translation_percent = 100 * t_sum / segment.count;
      segment.rotation_deg_per_m = r_sum / segment.count;
    }
    translation_sum += t_sum;
    rotation_sum += r_sum;
    result->num_segments += segment.count;
    result->lengths.push_back(segment);
  }
  if (result->num_segments > 0) {
    result->translation_percent = 100 * translation_sum / result->num_segments;
    result->rotation_deg_per_m = rotation_sum / result->num_segments;
  }
}

// The estimate moved by the Umeyama alignment of its positions onto the reference's.
Poses Align(const Poses& estimate,
            const Poses& reference,
            TrajectoryAlignment alignment,
            TrajectoryError* result) {
  Eigen::Matrix3Xd source(3, estimate.size()), target(3, reference.size());
  for (size_t k = 0; k < estimate.size(); ++k) {
    source.col(k) = estimate[k].translation();
    target.col(k) = reference[k].translation();
  }
  const Eigen::Matrix4d similarity =
      Eigen::umeyama(source, target, alignment == TrajectoryAlignment::kSimilarity);
  result->alignment_scale = similarity.block<3, 1>(0, 0).norm();
  result->reference_from_estimate.linear() = similarity.block<3, 3>(0, 0) / result->alignment_scale;
  result->reference_from_estimate.translation() = similarity.block<3, 1>(0, 3);
  Poses aligned;
  for (const Eigen::Isometry3d& pose : estimate) {
    Eigen::Isometry3d moved = result->reference_from_estimate * pose;
    moved.translation() =
        similarity.block<3, 3>(0, 0) * pose.translation() + similarity.block<3, 1>(0, 3);
    aligned.push_back(moved);
  }
  return aligned;
}

void AbsoluteErrors(const Poses& aligned, const Poses& reference, TrajectoryError* result) {
  double squares = 0;
  for (size_t k = 0; k < aligned.size(); ++k) {
    const double error = (aligned[k].translation() - reference[k].translation()).norm();
    result->position_errors_m.push_back(error);
    result->rotation_errors_deg.push_back(
        RotationAngleDeg(aligned[k].linear().transpose() * reference[k].linear()));
    squares += error * error;
  }
  result->position_rmse_m = std::sqrt(squares / aligned.size());
  result->position_mean_m =
      std::accumulate(result->position_errors_m.begin(), result->position_errors_m.end(), 0.0) /
      aligned.size();
  result->position_median_m = Median(result->position_errors_m);
  result->position_max_m =
      *std::max_element(result->position_errors_m.begin(), result->position_errors_m.end());
}

}  // namespace

bool TrajectoryErrorOptions::Check() const {
  for (const double length : lengths_m) LIDAR_CHECK_OPTION_GT(length, 0);
  return true;
}

double RotationAngleDeg(const Eigen::Matrix3d& rotation) {
  return Eigen::AngleAxisd(Eigen::Quaterniond(rotation).normalized()).angle() * 180.0 / M_PI;
}

TrajectoryError EvaluateTrajectoryError(const Poses& estimate,
                                        const Poses& reference,
                                        const TrajectoryErrorOptions& options) {
  ThrowUnlessValid(options, "TrajectoryErrorOptions");
  if (estimate.size() != reference.size() || reference.size() < 2) {
    throw std::invalid_argument("EvaluateTrajectoryError: " + std::to_string(estimate.size()) +
                                " estimated and " + std::to_string(reference.size()) +
                                " reference poses; the same number, at least 2, are needed");
  }
  TrajectoryError result;
  result.num_poses = reference.size();
  const std::vector<double> distances = Distances(reference);
  result.path_length_m = distances.back();
  const Poses aligned = Align(estimate, reference, options.alignment, &result);
  AbsoluteErrors(aligned, reference, &result);
  RelativeErrors(aligned, reference, distances, SegmentLengths(options, distances.back()), &result);
  for (size_t k = 1; k < reference.size(); ++k) {
    const Eigen::Isometry3d error = RelativeError(aligned, reference, k - 1, k);
    result.steps.push_back({distances[k],
                            distances[k] - distances[k - 1],
                            error.translation().norm(),
                            RotationAngleDeg(error.linear())});
  }
  if (result.path_length_m > 0) {
    result.end_to_end_drift_percent =
        100 * RelativeError(aligned, reference, 0, reference.size() - 1).translation().norm() /
        result.path_length_m;
  }
  return result;
}

}  // namespace colmap_lidar
