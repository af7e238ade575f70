// The steps of the pipeline as typed calls. Each step has its options (an algorithm's Options struct, or
// a small struct around it for what only the command needs), a function that registers them in a
// CommandOptions under a prefix, and a Run*Step function that prints progress and writes the
// step's outputs. A command (`colmap-lidar joint_adjuster ...`, commands.h) registers its step's options
// without a prefix; `pipeline` registers every step's options in one manager under the step's section
// ("JointAdjuster.hold_translation_mm", "StereoDepth.block_size", ...; COLMAP's own SiftExtraction.* etc. keep
// their names), so that an option on its command line or in its --project_path .ini reaches the step,
// as COLMAP's automatic_reconstructor does. Errors are thrown.
#pragma once

#include "bridge/baselines/edge_axis_profile.h"
#include "bridge/baselines/edge_calibration.h"
#include "bridge/dense/densifier.h"
#include "bridge/evaluation/trajectory_evaluation.h"
#include "bridge/exe/command_options.h"
#include "bridge/initialization/pose_initializer.h"
#include "bridge/initialization/selected_frames.h"
#include "bridge/joint/joint_adjuster.h"
#include "bridge/joint/joint_problem_data.h"
#include "bridge/pipeline/densifier_step.h"
#include "bridge/pipeline/evaluation_steps.h"
#include "bridge/pipeline/front_end_steps.h"
#include "bridge/pipeline/initialization_step.h"
#include "bridge/pipeline/joint_step.h"
#include "bridge/pipeline/lidar_registration_step.h"
#include "bridge/pipeline/select_frames_step.h"
#include "colmap_ext/dataset_import.h"
#include "colmap_ext/depth_prior_evaluation.h"
#include "colmap_ext/depth_prior_extractor.h"
#include "colmap_ext/elapsed.h"
#include "colmap_ext/station_dataset.h"
#include "colmap_ext/stereo_depth.h"
#include "lidar/lidar_odometry.h"
#include "lidar/lidar_pose_graph.h"
#include "lidar/model_evaluation.h"
#include "lidar/moving_points.h"
#include "lidar/revisit_closure.h"
#include "lidar/station_cloud.h"
#include "lidar/sweep_deskew.h"
#include "lidar/trajectory_refinement.h"

#include <chrono>
#include <optional>
#include <string>

namespace colmap_lidar {

// Registers options as "<prefix><name>" with their current values as defaults.
class PrefixedOptions {
 public:
  PrefixedOptions(CommandOptions* manager, std::string prefix)
      : manager_(manager), prefix_(std::move(prefix)) {}

  template <typename T>
  void Add(const std::string& name, T* value, const std::string& help = "") {
    manager_->AddDefaultOption(prefix_ + name, value, help);
  }
  template <typename Enum, size_t N>
  void AddChoice(const std::string& name,
                 Enum* value,
                 const NamedChoices<Enum, N>& table,
                 const std::string& help = "") {
    manager_->AddChoiceOption(prefix_ + name, value, table, help);
  }

 private:
  CommandOptions* manager_;
  std::string prefix_;
};

// Also registers COLMAP's SiftExtraction.*, SiftMatching.*, TwoViewGeometry.*, ExhaustiveMatching.*,
// SequentialMatching.* and SpatialMatching.* sections (CPU SIFT by default: a headless build has no
// OpenGL context); TakeColmapImportOptions copies them in after Parse(). With `choose_matcher`
// (the pipeline's), --matcher also takes "auto", which sets it.
void AddImportStepOptions(const std::string& prefix,
                          CommandOptions* manager,
                          ImportStepOptions* options,
                          bool* choose_matcher = nullptr);
void TakeColmapImportOptions(const CommandOptions& manager, ImportStepOptions* options);

// stereo_depth: SGM depth maps of every station.
void AddStereoDepthOptions(const std::string& prefix,
                           CommandOptions* manager,
                           StereoDepthOptions* options);

// depth_prior_extractor: depth priors of the database's keypoints.
void AddDepthPriorOptions(const std::string& prefix,
                          CommandOptions* manager,
                          DepthPriorOptions* options);

// lidar_registrator (LidarRegistratorStepOptions, RunLidarRegistratorStep:
// bridge/pipeline/lidar_registration_step.h).
void AddLidarRegistratorOptions(const std::string& prefix,
                                CommandOptions* manager,
                                LidarRegistratorStepOptions* options);

// select_frames: the frames of a drive that go on to the camera steps (selected_frames.h), from
// lidar_registrator's output folder into OUTPUT.
void AddFrameSelectionOptions(const std::string& prefix,
                              CommandOptions* manager,
                              FrameSelectionOptions* options);

// pose_initializer: initial poses, cam_from_lidar and landmarks; or an existing model rescaled.
void AddPoseInitializerOptions(const std::string& prefix,
                               CommandOptions* manager,
                               PoseInitializerOptions* options);
// Help of the joint_adjuster and densifier commands' --registration_path.
inline constexpr char kRegistrationPathHelp[] =
    "lidar_registrator's output: its static/ (moving points removed) or deskewed/ clouds replace "
    "the "
    "dataset's; empty: the dataset's clouds";

// joint_adjuster: the joint problem on a sparse model (JointAdjusterStepOptions, RunJointAdjusterStep:
// bridge/pipeline/joint_step.h).
void AddJointAdjusterOptions(const std::string& prefix,
                             CommandOptions* manager,
                             JointAdjusterStepOptions* options);
// Throws std::invalid_argument naming the first of argv that is an option joint_adjuster no longer
// takes (under `prefix`, e.g. "JointAdjuster." in the pipeline), on the command line or in the project
// file of --project_path, and what decides its value now.
void RefuseRemovedJointAdjusterOptions(int argc, char** argv, const std::string& prefix);
// densifier: the dense model.
void AddDensifierOptions(const std::string& prefix,
                         CommandOptions* manager,
                         DensifierOptions* options);
// calibrate_edges --profile_axis: J along the rotation about one camera axis instead of the grid.
struct EdgeAxisProfileRequest {
  Eigen::Vector3d axis_in_cam;
  EdgeAxisProfileOptions options;
};

struct EdgeCalibrationPaths {
  std::string dataset_path;
  // A sparse model: only its registered stations; empty: all stations.
  std::string input_path;
  // The start (qw qx qy qz tx ty tz); empty: rig.json's guess.
  std::string cam_from_lidar_path;
  std::string output_path;
  // lidar_registrator's output, whose static (de-skewed) clouds replace the dataset's; empty: the
  // dataset's clouds.
  std::string registration_path;
};

// calibrate_edges: cam_from_lidar by Levinson & Thrun's edge alignment from a start, over the
// stations. `profile`: the start turned about one axis only.
void RunCalibrateEdgesStep(const EdgeCalibrationPaths& paths,
                           const EdgeCalibrationOptions& options,
                           const std::optional<EdgeAxisProfileRequest>& profile = std::nullopt);

// "0.002,0.005,0.01" -> numbers. Every token must be a positive number in full ("2mm" is refused,
// not read as 2); an empty result means the list was malformed.
std::vector<double> ParsePositiveNumbers(const std::string& csv);

// evaluate_model's options but the thresholds (a list, parsed by the command).
void AddModelEvaluationOptions(const std::string& prefix,
                               CommandOptions* manager,
                               ModelEvaluationOptions* options);
}  // namespace colmap_lidar
