// The survey planner: before anyone goes to the field, predicts how well a planned set of stations
// will calibrate cam_from_lidar, and which one extra station would help most.
//
// For the planned station poses, the capture is simulated with the sensor pod's model (keypoints
// with pixel noise, depth priors with noise of their own sigma_d, LiDAR scans with range noise; no
// images, no SIFT: bridge/survey/synthetic_joint_problem.h) and the joint problem is solved at the
// true poses. What is reported is the joint adjuster's own uncertainty of T_e (its cluster-robust
// covariance with the residuals grouped by landmark only: the simulated noise is independent between
// stations; its coverage over seeded draws: tests/joint_adjuster_coverage_test.cc), its unobservable
// directions in words, and the motion test of Zhen et al. 2019 (stations must rotate about two
// non-parallel axes).
//
// Candidates: stations on a ring around the structure at the plan's mean distance, each level (like
// a tripod station) and tilted (low, looking up, rolled). Each candidate is added to the plan in turn
// and the prediction repeated; they are ranked by the worst ratio sigma / threshold over the six axes
// (the thresholds that call a direction unobservable: 0.2 deg, 5 mm by default).
#pragma once

#include "bridge/joint/extrinsic_observability.h"
#include "bridge/joint/joint_adjuster.h"
#include "bridge/simulation/scene.h"
#include "bridge/survey/synthetic_joint_problem.h"
#include "lidar/point_cloud.h"

#include "colmap/geometry/rigid3.h"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace colmap_lidar {
namespace sim {

// The structure to survey: the world the capture is simulated in, and where the structure stands
// (for the candidate stations).
struct SurveyTarget {
  SyntheticWorld world;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // the candidates look at it
  double height = 0;                                 // above ground_z
  double ground_z = 0;
};

// One of the simulator's scenes (it must outlive the target).
SurveyTarget TargetOfScene(const Scene& scene);
// A structure given as points (world frame, z up; e.g. a prior scan): the ground is a plane at its
// lowest point.
SurveyTarget TargetOfSurface(std::shared_ptr<const PointCloud> surface);

struct SurveyPlanOptions {
  // The predicted capture's noise: keypoints [px], depth priors [their sigma_d], LiDAR range [m].
  double pixel_noise = 0.5;
  double depth_noise_sigmas = 1.0;
  double lidar_range_noise_m = 0.01;
  // Points per simulated LiDAR scan; every landmark_stride-th surface sample a landmark.
  size_t lidar_points = 60000;
  int landmark_stride = 6;
  // Candidate positions on the ring around the structure (each gives a level and a tilted station).
  int num_candidate_positions = 4;
  // The tilted candidates: pitched up from this height by the angle to the structure plus
  // candidate_tilt_deg, and rolled by candidate_tilt_deg.
  double candidate_tilt_deg = 10.0;
  double tilted_height_m = 0.45;
  uint64_t seed = 1;
  // The joint adjustment (hold_unobservable is turned off: the planner reports, it does not hold;
  // the covariance's residuals grouped by landmark only).
  JointAdjusterOptions adjuster = DefaultAdjusterOptions();

  static JointAdjusterOptions DefaultAdjusterOptions();
  bool Check() const;
};

struct CalibrationPrediction {
  MotionAnalysis motion;
  // Covariance of (rotation vector [deg], translation [mm]) of cam_from_lidar about / along the
  // camera axes; the sentences naming unobservable directions.
  ExtrinsicUncertainty uncertainty;
  Eigen::Vector3d rotation_sigma_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation_sigma_mm = Eigen::Vector3d::Zero();
  // max over the six axes of sigma / its unobservable threshold (above 1: an axis is unobservable).
  double worst_ratio = 0;
  std::string worst_axis;  // "rotation about x", "translation along y", ...
};

struct CandidateStation {
  colmap::Rigid3d cam_from_world;
  std::string description;
  CalibrationPrediction prediction;  // of the plan with this station added
};

struct SurveyPlan {
  CalibrationPrediction planned;
  std::vector<CandidateStation> candidates;  // best (lowest worst_ratio) first
};

// The prediction for `stations` (cam_from_world of the left camera; at least 2).
CalibrationPrediction PredictCalibration(const SurveyTarget& target,
                                         const std::vector<colmap::Rigid3d>& stations,
                                         const SurveyPlanOptions& options);

// The candidate stations around the structure for a plan (see the file comment).
std::vector<CandidateStation> CandidateStations(const SurveyTarget& target,
                                                const std::vector<colmap::Rigid3d>& stations,
                                                const SurveyPlanOptions& options);

// The prediction for the plan and for the plan plus each candidate, ranked. `progress` (may be
// empty) is called after each prediction with (done, total).
SurveyPlan PlanSurvey(const SurveyTarget& target,
                      const std::vector<colmap::Rigid3d>& stations,
                      const SurveyPlanOptions& options,
                      const std::function<void(int, int)>& progress = {});

}  // namespace sim
}  // namespace colmap_lidar
