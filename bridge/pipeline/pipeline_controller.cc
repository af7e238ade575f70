#include "bridge/pipeline/pipeline_controller.h"

#include "bridge/initialization/lidar_registration_files.h"
#include "bridge/pipeline/evaluation_steps.h"
#include "bridge/pipeline/step_resources.h"
#include "bridge/pipeline/workspace_lock.h"
#include "colmap_ext/logging.h"
#include "lidar/util/atomic_file.h"
#include "lidar/util/check_option.h"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

struct PipelineStep {
  std::string name;
  std::function<void()> run;
};

// The workspace layout WS/{database.db, stereo, lidar, lidar_selected, sparse/initial,
// sparse/joint, dense, evaluation}.
struct WorkspacePaths {
  explicit WorkspacePaths(const fs::path& ws)
      : database((ws / "database.db").string()),
        stereo((ws / "stereo").string()),
        lidar((ws / "lidar").string()),
        selected((ws / "lidar_selected").string()),
        initial((ws / "sparse" / "initial").string()),
        joint((ws / "sparse" / "joint").string()),
        dense((ws / "dense").string()),
        evaluation((ws / "evaluation").string()) {}
  std::string database, stereo, lidar, selected, initial, joint, dense, evaluation;
};

// Frames of a moving platform are selected for the camera steps; tripod stations are each meant.
bool SelectsFrames(const StationDataset& dataset, const PipelineOptions& options) {
  return dataset.rig.IsMovingPlatform() || options.registrator.deskew_sweeps;
}

// The LiDAR trajectory (lidar_poses.txt, against the reference moved to the LiDAR by the reference
// extrinsic) and the joint model's camera poses against the dataset's reference trajectory.
std::vector<PipelineStep> TrajectoryEvaluationSteps(const StationDataset& dataset,
                                                    const WorkspacePaths& paths) {
  TrajectoryEvaluationStepOptions camera;
  camera.reference_path = dataset.GroundTruthPath("cam_from_world.txt");
  camera.trajectory_path = paths.joint;
  camera.output_path = (fs::path(paths.evaluation) / "camera_trajectory").string();
  std::vector<PipelineStep> steps;
  if (dataset.HasReferenceExtrinsic()) {
    TrajectoryEvaluationStepOptions lidar = camera;
    lidar.trajectory_path = (fs::path(paths.lidar) / "lidar_poses.txt").string();
    lidar.reference_sensor_from_sensor_path = dataset.GroundTruthPath("cam_from_lidar.txt");
    lidar.output_path = (fs::path(paths.evaluation) / "lidar_trajectory").string();
    steps.push_back({"evaluate_lidar_trajectory", [=] { RunEvaluateTrajectoryStep(lidar); }});
  }
  steps.push_back({"evaluate_camera_trajectory", [=] { RunEvaluateTrajectoryStep(camera); }});
  return steps;
}

// The evaluation steps: what the dataset's ground truth holds.
std::vector<PipelineStep> EvaluationSteps(const StationDataset& dataset,
                                          const PipelineOptions& options) {
  const WorkspacePaths paths(options.workspace_path);
  const std::string &database = paths.database, &joint = paths.joint, &dense = paths.dense,
                    &evaluation = paths.evaluation;
  const bool stereo_rig = dataset.rig.IsStereo();
  std::vector<PipelineStep> steps;
  // A KITTI drive: the reference extrinsic only.
  if (dataset.HasReferenceExtrinsic()) {
    steps.push_back({"evaluate_calibration", [=, &dataset] {
                       RunEvaluateCalibrationStep(
                           dataset.root, joint, "", evaluation, TrajectoryAlignment::kRigid);
                     }});
  }
  // The simulator's true depth maps: how far the stereo depth priors are from the truth.
  if (stereo_rig && fs::is_directory(dataset.GroundTruthPath("depth"))) {
    steps.push_back({"evaluate_depth_priors", [=, &dataset] {
                       RunEvaluateDepthPriorsStep(database,
                                                  dataset.root,
                                                  (fs::path(evaluation) / "depth_priors").string(),
                                                  DepthPriorEvaluationOptions());
                     }});
  }
  // ... and how far the dense depth maps are from them, wherever the model is (a drive too).
  if (fs::is_directory(dataset.GroundTruthPath("depth"))) {
    steps.push_back({"evaluate_dense_depth", [=, &dataset] {
                       RunEvaluateDenseDepthStep(
                           dense, dataset.root, (fs::path(evaluation) / "dense_depth").string());
                     }});
  }
  if (dataset.HasGroundTruth()) {
    const std::vector<PipelineStep> trajectory_steps = TrajectoryEvaluationSteps(dataset, paths);
    steps.insert(steps.end(), trajectory_steps.begin(), trajectory_steps.end());
  }
  if (!dataset.HasGroundTruth() || !fs::is_regular_file(dataset.GroundTruthPath("surface.ply"))) {
    return steps;
  }
  steps.push_back({"evaluate_model", [=, &dataset] {
                     RunEvaluateModelStep((fs::path(dense) / "fused.ply").string(),
                                          dataset.GroundTruthPath("surface.ply"),
                                          (fs::path(evaluation) / "truth_from_model.txt").string(),
                                          (fs::path(evaluation) / "model").string(),
                                          options.evaluation);
                   }});
  return steps;
}

// pose_initializer, joint_adjuster and densifier on the camera steps' dataset (`camera_dataset`) with
// the registrator's clouds; the initialiser's edges from `registration`. The capture profile passes
// from the pose initialiser to the joint step in memory; a rerun that skips the initialiser reads
// the one it recorded.
std::vector<PipelineStep> BackEndSteps(const WorkspacePaths& paths,
                                       const std::function<StationDataset()>& camera_dataset,
                                       const std::string& registration,
                                       bool stereo_rig,
                                       const PipelineOptions& options) {
  const std::function<StationDataset()> clouds = [=] {
    return WithRegistratorClouds(camera_dataset(), paths.lidar);
  };
  const std::string stereo = stereo_rig ? paths.stereo : "";
  const auto profile = std::make_shared<std::optional<CaptureProfile>>();
  return {
      {"pose_initializer",
       [=] {
         *profile =
             RunPoseInitializerStep(clouds(),
                                    {paths.database, registration, "", paths.initial, stereo},
                                    options.initializer);
       }},
      {"joint_adjuster",
       [=] {
         JointAdjusterStepOptions joint_options = options.joint;
         joint_options.profile = *profile;
         joint_options.use_guess = options.initializer.use_guess;
         RunJointAdjusterStep(
             clouds(), {paths.database, paths.initial, "", paths.joint}, joint_options);
       }},
      {"densifier",
       [=] {
         RunDensifierStep(clouds(), {paths.joint, "", stereo, paths.dense}, options.densifier);
       }},
  };
}

// The steps in order, on the workspace layout (WorkspacePaths); the evaluation steps only when the
// dataset has ground truth.
std::vector<PipelineStep> PipelineSteps(const StationDataset& dataset,
                                        const PipelineOptions& options) {
  const WorkspacePaths paths(options.workspace_path);
  const std::string &database = paths.database, &stereo = paths.stereo, &lidar = paths.lidar;
  // A monocular rig has no stereo steps and no stereo depth for the densifier.
  const bool stereo_rig = dataset.rig.IsStereo();
  // With frame selection the camera steps see the selected frames and their registration folder
  // (read when they run: the selection is made by a step before them).
  const bool select = SelectsFrames(dataset, options);
  const std::string registration = select ? paths.selected : lidar;
  const std::function<StationDataset()> camera_dataset = [=, &dataset] {
    return select ? RestrictToStations(dataset, ReadSelectedFrames(paths.selected)) : dataset;
  };
  const PipelineStep registrator = {
      "lidar_registrator", [=, &dataset] {
        RunLidarRegistratorStep(
            (fs::path(dataset.root) / "lidar").string(), lidar, options.registrator);
      }};
  // The spatial matcher matches only images of stations near in the LiDAR registration: the LiDAR
  // registration runs first (no N^2 image pairs on large surveys).
  const bool lidar_first = options.import.import.matcher == ImageMatcher::kSpatial || select;
  std::vector<PipelineStep> steps;
  if (lidar_first) steps.push_back(registrator);
  if (select) {
    steps.push_back(
        {"select_frames", [=] { RunSelectFramesStep(lidar, paths.selected, options.selection); }});
  }
  steps.push_back(
      {"import_dataset", [=] { RunImportStep(camera_dataset(), database, options.import); }});
  if (stereo_rig) {
    steps.push_back(
        {"stereo_depth", [=] { RunStereoDepthStep(camera_dataset(), stereo, options.stereo); }});
    steps.push_back({"depth_prior_extractor",
                     [=] { RunDepthPriorStep(database, stereo, options.depth_prior); }});
  }
  if (!lidar_first) steps.push_back(registrator);
  const std::vector<PipelineStep> back_end =
      BackEndSteps(paths, camera_dataset, registration, stereo_rig, options);
  steps.insert(steps.end(), back_end.begin(), back_end.end());
  const std::vector<PipelineStep> evaluation_steps = EvaluationSteps(dataset, options);
  steps.insert(steps.end(), evaluation_steps.begin(), evaluation_steps.end());
  return steps;
}

struct StepRecord {
  std::string name;
  std::string status;  // ran | skipped
  double wall_s = 0, cpu_s = 0, peak_mib = 0;
};

// WS/pipeline_steps.csv, rewritten after every step: what each step cost (scripts/benchmark_pipeline.sh
// reads it).
void WriteStepTable(const fs::path& ws, const std::vector<StepRecord>& records) {
  std::ostringstream csv;
  csv << "# step, status, wall seconds, CPU seconds (all threads), peak resident MiB of the step\n"
      << std::fixed << std::setprecision(1);
  for (const StepRecord& r : records) {
    csv << r.name << "," << r.status << "," << r.wall_s << "," << r.cpu_s << "," << r.peak_mib
        << "\n";
  }
  WriteFileAtomically((ws / "pipeline_steps.csv").string(), csv.str());
}

// Runs the steps not marked done in WS/steps (all with `overwrite`), marks each when it ends and
// prints what each cost.
void RunSteps(const std::vector<PipelineStep>& steps, const fs::path& ws, bool overwrite) {
  std::vector<StepRecord> records;
  for (size_t k = 0; k < steps.size(); ++k) {
    const PipelineStep& step = steps[k];
    const fs::path marker = ws / "steps" / (step.name + ".done");
    std::cout << "== [" << k + 1 << "/" << steps.size() << "] " << step.name;
    if (fs::exists(marker) && !overwrite) {
      std::cout << ": done before, skipped (--overwrite 1 reruns it)" << std::endl;
      records.push_back({step.name, "skipped"});
      continue;
    }
    std::cout << std::endl;
    fs::remove(marker);
    if (step.name == "import_dataset" && overwrite) fs::remove(ws / "database.db");
    const StepResources resources;
    try {
      step.run();
    } catch (const std::exception& error) {
      throw std::runtime_error("step " + step.name + " failed: " + error.what());
    }
    WriteFileAtomically(marker.string(), step.name + " finished\n");
    records.push_back({step.name,
                       "ran",
                       resources.WallSeconds(),
                       resources.CpuSeconds(),
                       resources.PeakResidentMiB()});
    WriteStepTable(ws, records);
  }
  std::cout << "\n== Pipeline summary (" << ws.string() << "): wall s, CPU s, peak MiB\n";
  size_t name_width = 0;
  for (const StepRecord& r : records) name_width = std::max(name_width, r.name.size() + 2);
  for (const StepRecord& r : records) {
    std::cout << "  " << std::left << std::setw(static_cast<int>(name_width)) << r.name
              << std::setw(9) << r.status << std::right << std::fixed << std::setprecision(1)
              << std::setw(8) << r.wall_s << std::setw(9) << r.cpu_s << std::setw(9)
              << std::setprecision(0) << r.peak_mib << "\n";
  }
}

// Import.matcher spatial without a registration path: the pipeline's own LiDAR registration (of
// the selected frames), which then runs before the import (PipelineSteps).
void SetSpatialMatchingRegistration(const StationDataset& dataset, PipelineOptions* pipeline) {
  if (pipeline->import.import.matcher != ImageMatcher::kSpatial ||
      !pipeline->import.lidar_registration_path.empty()) {
    return;
  }
  const WorkspacePaths paths(pipeline->workspace_path);
  pipeline->import.lidar_registration_path =
      SelectsFrames(dataset, *pipeline) ? paths.selected : paths.lidar;
}

// Import.matcher auto (see PipelineOptions::max_exhaustive_stations).
void ResolveAutoMatcher(size_t num_stations, PipelineOptions* pipeline) {
  if (!pipeline->choose_matcher) return;
  const bool exhaustive = num_stations <= static_cast<size_t>(pipeline->max_exhaustive_stations);
  pipeline->import.import.matcher = exhaustive ? ImageMatcher::kExhaustive : ImageMatcher::kSpatial;
  std::cout << "Import.matcher auto: " << num_stations << " stations, "
            << (exhaustive ? "exhaustive matching"
                           : "spatial matching (each image with its " +
                                 std::to_string(
                                     pipeline->import.import.spatial_matching.max_num_neighbors) +
                                 " nearest stations of the LiDAR registration)")
            << std::endl;
}

// Every step's options checked before the first step runs; the mode into the steps it concerns.
void CheckStepOptions(PipelineOptions* pipeline) {
  pipeline->joint.adjuster.mode = pipeline->mode;
  if (pipeline->mode == JointMode::kStereoOnly) pipeline->densifier.refine_with_lidar = false;
  THROW_CHECK(pipeline->stereo.Check());
  THROW_CHECK(pipeline->depth_prior.Check());
  THROW_CHECK(pipeline->registrator.Check());
  THROW_CHECK(pipeline->initializer.Check());
  THROW_CHECK(pipeline->joint.Check());
  THROW_CHECK(pipeline->densifier.Check());
  ThrowUnlessValid(pipeline->selection, "FrameSelection");
}

// What the dataset decides: the import's matcher (checked once chosen for the dataset's size), the
// de-skewing of sweeps rig.json declares, the sweeps' times.
void DecideFromDataset(const StationDataset& dataset, PipelineOptions* pipeline) {
  ResolveAutoMatcher(dataset.stations.size(), pipeline);
  SetSpatialMatchingRegistration(dataset, pipeline);
  THROW_CHECK(pipeline->import.Check());
  if (!dataset.rig.IsStereo() && pipeline->mode == JointMode::kStereoOnly) {
    throw std::invalid_argument("--mode stereo_only needs a stereo rig; " + dataset.root +
                                "/rig.json has one camera");
  }
  LidarRegistratorStepOptions& registrator = pipeline->registrator;
  if (dataset.rig.lidar_sweep && !registrator.deskew_sweeps) {
    // rig.json says the clouds are sweeps of a moving platform (import_kitti writes it).
    registrator.deskew_sweeps = true;
    registrator.sweep_timing.start_azimuth_deg = dataset.rig.lidar_sweep->start_azimuth_deg;
    registrator.sweep_timing.counter_clockwise = dataset.rig.lidar_sweep->counter_clockwise;
    std::cout << dataset.root
              << "/rig.json: the clouds are sweeps of a moving platform (lidar.sweep): "
                 "lidar_registrator de-skews them"
              << std::endl;
  }
  registrator.station_times = dataset.frame_times;
  registrator.moving_platform = dataset.rig.IsMovingPlatform();
  if (!dataset.sweep_times.empty()) {
    registrator.sweep_clock = SweepClock(dataset);
    std::cout << dataset.root << "/sweep_times.txt times the sweeps" << std::endl;
  }
}

// The steps up to and including `stop_after` (all of them when it is empty); an unknown name is an
// error listing the dataset's steps.
std::vector<PipelineStep> StepsUpTo(std::vector<PipelineStep> steps,
                                    const std::string& stop_after) {
  if (stop_after.empty()) return steps;
  std::string names;
  for (size_t k = 0; k < steps.size(); ++k) {
    if (steps[k].name == stop_after) {
      steps.resize(k + 1);
      return steps;
    }
    names += (names.empty() ? "" : ", ") + steps[k].name;
  }
  throw std::invalid_argument("--stop_after " + stop_after +
                              ": not a step of this dataset's pipeline (" + names + ")");
}

}  // namespace

PipelineOptions::PipelineOptions() {
  // At 3 MP COLMAP's 8192 SIFT features (more with their second orientations) make matching the
  // import's cost; with 4096 the LiDAR, not the feature count, still sets the accuracy of
  // cam_from_lidar (docs/benchmarks/pipeline.md). Images of up to 1 MP rarely have more.
  import.import.sift_extraction.max_num_features = 4096;
  // GPU SIFT needs CUDA or an OpenGL context; a headless build has neither.
  import.import.sift_extraction.use_gpu = false;
  import.import.sift_matching.use_gpu = false;
  import.import.spatial_matching.max_num_neighbors = 12;
  // All pairs grow as N^2: the pipeline registers each station with its 4 most similar ones.
  registrator.max_neighbors = 4;
}

void RunFullPipeline(PipelineOptions pipeline) {
  CheckStepOptions(&pipeline);
  const StationDataset dataset = ReadStationDataset(pipeline.dataset_path);
  DecideFromDataset(dataset, &pipeline);
  const std::vector<PipelineStep> steps =
      StepsUpTo(PipelineSteps(dataset, pipeline), pipeline.stop_after);
  const fs::path ws(pipeline.workspace_path);
  const WorkspaceLock lock(pipeline.workspace_path);
  fs::create_directories(ws / "steps");
  fs::create_directories(ws / "sparse");
  RunSteps(steps, ws, pipeline.overwrite);
  if (!pipeline.stop_after.empty()) {
    std::cout << "  stopped after " << pipeline.stop_after << " (--stop_after)" << std::endl;
    return;
  }
  std::cout << "  model: " << (ws / "sparse" / "joint").string()
            << " (cam_from_lidar.txt, report.json)\n"
            << "  dense: " << (ws / "dense").string()
            << " (fused.ply, lidar_map.ply, COLMAP dense workspace)" << std::endl;
}

}  // namespace colmap_lidar
