// Errors of an estimated trajectory against a reference: poses world_from_sensor of the same frames
// of the same sensor, in time order (index k of one is index k of the other).
//
// Relative error, KITTI's metric (Geiger, Lenz, Urtasun, CVPR 2012): for every first frame i and
// segment length L, j is the first frame whose path length along the reference from i reaches L;
// with the relative motions A = est_i^-1 est_j and B = ref_i^-1 ref_j and E = A^-1 B,
//   translation error = |t(E)| / L   (reported in %),   rotation error = angle(E) / L   (deg/m),
// averaged over all (i, L) samples; per length and over all lengths.
// Per-step error: E of consecutive frames, |t(E)| [m] and angle(E) [deg].
// Absolute error: camera positions after a rigid (or, for a trajectory of unknown scale, a
// similarity) alignment of the estimate onto the reference (Umeyama, least squares on positions);
// with a similarity the relative errors are measured on the scaled estimate.
// End-to-end drift: |t(E)| of the first and last frame over the reference's path length (%).
#pragma once

#include "lidar/util/named_choice.h"

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace colmap_lidar {

enum class TrajectoryAlignment { kRigid, kSimilarity };
inline constexpr NamedChoices<TrajectoryAlignment, 2> kTrajectoryAlignmentNames = {
    {{"rigid", TrajectoryAlignment::kRigid}, {"similarity", TrajectoryAlignment::kSimilarity}}};
inline std::string TrajectoryAlignmentName(TrajectoryAlignment alignment) {
  return ChoiceName(kTrajectoryAlignmentNames, alignment);
}

struct TrajectoryErrorOptions {
  // Segment lengths [m]; empty: 10, 20, ... up to the reference's path length (at most 800).
  std::vector<double> lengths_m;
  TrajectoryAlignment alignment = TrajectoryAlignment::kRigid;

  bool Check() const;
};

struct SegmentLengthError {
  double length_m = 0;
  int count = 0;  // (i, L) samples: first frames whose segment of this length ends in the drive
  double translation_percent = 0;
  double rotation_deg_per_m = 0;
};

struct StepError {
  double distance_m = 0;  // along the reference, at the step's end
  double length_m = 0;    // of the reference's step
  double translation_error_m = 0;
  double rotation_error_deg = 0;
};

struct TrajectoryError {
  size_t num_poses = 0;
  double path_length_m = 0;  // of the reference
  // Over all (i, L) samples; 0 samples (a path shorter than every length): both 0 with count 0.
  int num_segments = 0;
  double translation_percent = 0;
  double rotation_deg_per_m = 0;
  std::vector<SegmentLengthError> lengths;
  std::vector<StepError> steps;
  double end_to_end_drift_percent = 0;
  // The alignment reference_world_from_estimate_world: rotation and translation, and the scale (1 rigid).
  Eigen::Isometry3d reference_from_estimate = Eigen::Isometry3d::Identity();
  double alignment_scale = 1;
  std::vector<double> position_errors_m;    // per pose, after the alignment
  std::vector<double> rotation_errors_deg;  // per pose, after the alignment
  double position_rmse_m = 0, position_mean_m = 0, position_median_m = 0, position_max_m = 0;
};

// Throws std::invalid_argument for trajectories of different sizes or fewer than 2 poses, and for
// invalid options.
TrajectoryError EvaluateTrajectoryError(const std::vector<Eigen::Isometry3d>& estimate,
                                        const std::vector<Eigen::Isometry3d>& reference,
                                        const TrajectoryErrorOptions& options);

// The angle of a rotation [deg], robust near 0 and 180 deg.
double RotationAngleDeg(const Eigen::Matrix3d& rotation);

}  // namespace colmap_lidar
