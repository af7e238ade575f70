// The evaluation steps as library calls: what a run is measured against when the dataset has a
// reference (the simulator's truth, KITTI's calibration and poses): cam_from_lidar and station
// poses (evaluate_calibration), a trajectory (evaluate_trajectory), the depth priors and the dense
// depth maps against true depth maps, and the dense model against the true surface
// (evaluate_model). Each writes metrics.json (and plots) into its output folder and prints a
// summary.
#pragma once

#include "bridge/evaluation/calibration_evaluation.h"
#include "bridge/evaluation/trajectory_evaluation.h"
#include "colmap_ext/dense_depth_evaluation.h"
#include "colmap_ext/depth_prior_evaluation.h"
#include "lidar/model_evaluation.h"
#include "lidar/trajectory_error.h"

#include <string>
#include <vector>

namespace colmap_lidar {

// evaluate_calibration: cam_from_lidar and station poses against ground_truth/. `output_path` empty:
// print the metrics only. `alignment`: rigid | similarity.
void RunEvaluateCalibrationStep(const std::string& dataset_path,
                                const std::string& input_path,
                                const std::string& cam_from_lidar_path,
                                const std::string& output_path,
                                TrajectoryAlignment alignment);

// evaluate_trajectory: a trajectory against a reference
// (bridge/evaluation/trajectory_evaluation.h).
struct TrajectoryEvaluationStepOptions {
  std::string trajectory_path, reference_path, output_path;
  TrajectorySource trajectory_format = TrajectorySource::kAuto;
  TrajectorySource reference_format = TrajectorySource::kAuto;
  // A pose file reference_sensor_from_sensor applied to every reference pose (empty: same sensor).
  std::string reference_sensor_from_sensor_path;
  // A dataset whose timestamps.txt times named poses (empty: none).
  std::string timestamps_path;
  TrajectoryAlignment alignment = TrajectoryAlignment::kRigid;
  std::vector<double> lengths_m;  // empty: 10, 20, ... m
  double max_time_difference_s = 0.01;

  bool Check() const;
};
TrajectoryError RunEvaluateTrajectoryStep(const TrajectoryEvaluationStepOptions& options);

// evaluate_depth_priors: the database's priors against DATASET/ground_truth/depth/, metrics.json
// and a histogram into `output_path`.
void RunEvaluateDepthPriorsStep(const std::string& database_path,
                                const std::string& dataset_path,
                                const std::string& output_path,
                                const DepthPriorEvaluationOptions& options);

// evaluate_dense_depth: DENSE's depth maps against DATASET/ground_truth/depth/, metrics.json and a
// histogram into `output_path`.
void RunEvaluateDenseDepthStep(const std::string& dense_path,
                               const std::string& dataset_path,
                               const std::string& output_path);

// evaluate_model: a cloud against ground_truth/surface.ply. `truth_from_model_path` may be empty.
void RunEvaluateModelStep(const std::string& model_path,
                          const std::string& ground_truth_path,
                          const std::string& truth_from_model_path,
                          const std::string& output_path,
                          const ModelEvaluationOptions& options);

}  // namespace colmap_lidar
