// The pipeline as a library controller: every step of bridge/pipeline/ in order on one workspace
// WS/{database.db, stereo, lidar, lidar_selected, sparse/initial, sparse/joint, dense, evaluation},
// the evaluation steps when the dataset has a reference. A step marked done in WS/steps is skipped
// (a rerun continues where a run stopped); WS/pipeline_steps.csv records what each step cost.
// `colmap-lidar pipeline` parses its options into PipelineOptions and calls RunFullPipeline.
#pragma once

#include "bridge/pipeline/densifier_step.h"
#include "bridge/pipeline/front_end_steps.h"
#include "bridge/pipeline/initialization_step.h"
#include "bridge/pipeline/joint_step.h"
#include "bridge/pipeline/lidar_registration_step.h"
#include "bridge/pipeline/select_frames_step.h"
#include "lidar/model_evaluation.h"

#include <string>

namespace colmap_lidar {

// The options of `pipeline`: its own, and every step's under the step's section.
struct PipelineOptions {
  // The steps' defaults, but where the pipeline's differ: 4096 SIFT features, CPU SIFT, Import.matcher
  // auto with 12 spatial neighbours, each station registered with its 4 most similar ones.
  PipelineOptions();

  std::string dataset_path;
  std::string workspace_path;
  bool overwrite = false;
  // The name of the last step to run (empty: every step), e.g. pose_initializer for the initial
  // model alone; the steps after it are left for a later run.
  std::string stop_after;
  // The joint step's mode; stereo_only also fuses the unrefined stereo (no LiDAR in the densifier).
  JointMode mode = JointMode::kJoint;
  ImportStepOptions import;
  StereoDepthOptions stereo;
  DepthPriorOptions depth_prior;
  LidarRegistratorStepOptions registrator;
  PoseInitializerOptions initializer;
  JointAdjusterStepOptions joint;
  DensifierOptions densifier;
  ModelEvaluationOptions evaluation;
  // Which frames of a moving platform's drive go on to the camera steps (select_frames).
  FrameSelectionOptions selection;
  // Import.matcher auto: the import's matcher chosen by the number of stations, COLMAP's exhaustive
  // matcher up to max_exhaustive_stations; beyond, the spatial matcher on the LiDAR registration's
  // station positions (each image with its SpatialMatching.max_num_neighbors nearest), so that
  // image pairs grow as N, not N^2. Otherwise import.import.matcher.
  bool choose_matcher = true;
  int max_exhaustive_stations = 16;
};

// Checks every step's options first, decides what the dataset asks for (Import.matcher auto by the
// number of stations, the spatial matcher's registration, de-skewing when rig.json says the clouds
// are sweeps, the sweeps' times), takes the workspace's lock (one pipeline per workspace), runs the
// steps not done before (all of them with `overwrite`) and prints what each cost. Throws on the
// first step that fails, naming it.
void RunFullPipeline(PipelineOptions options);

}  // namespace colmap_lidar
