// pose_initializer and pipeline: from raw stations to a metric sparse model with cam_from_lidar.
#include "bridge/exe/commands.h"
#include "bridge/exe/step_resources.h"
#include "bridge/exe/steps.h"
#include "bridge/exe/workspace_lock.h"
#include "bridge/initialization/lidar_registration_files.h"
#include "bridge/initialization/model_completion.h"
#include "bridge/initialization/pose_initializer.h"
#include "bridge/initialization/selected_frames.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/util/check_option.h"

#include "colmap/controllers/option_manager.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <tuple>
#include <vector>

namespace colmap_lidar {
namespace fs = std::filesystem;

void AddPoseInitializerOptions(const std::string& prefix,
                               colmap::OptionManager* manager,
                               PoseInitializerOptions* options) {
  PrefixedOptions add(manager, prefix);
  add.Add("use_guess",
          &options->use_guess,
          "use rig.json's cam_from_lidar_guess if present (0: hand-eye)");
  add.Add("min_pair_inliers", &options->image_pairs.min_inliers);
  add.Add("max_lidar_image_angle_deg",
          &options->max_lidar_image_angle_deg,
          "a LiDAR edge whose rotation angle differs from the image edge's by more is left out");
  add.Add("use_degenerate_lidar_edges",
          &options->use_degenerate_lidar_edges,
          "LiDAR edges with a weakly constrained direction in the pose graph (0: left out)");
  add.Add("max_cycle_translation_m",
          &options->mixed_cycles.max_translation_m,
          "image and LiDAR edges: an edge breaking every cycle it is on by more is left out");
  add.Add("max_cycle_rotation_deg", &options->mixed_cycles.max_rotation_deg);
  add.Add("align_stereo_with_lidar",
          &options->align_stereo_with_lidar,
          "with stereo depth: refine the start by aligning each station's stereo depth with its "
          "LiDAR cloud (no motion needed)");
  add.Add("stereo_alignment_max_depth_m", &options->stereo_alignment.max_depth_m);
  add.Add("stereo_alignment_pixel_stride", &options->stereo_alignment.pixel_stride);
  add.Add("stereo_alignment_sigma_disparity_px", &options->stereo_alignment.sigma_disparity_px);
  add.Add("sigma_rotation_deg", &options->sigma_rotation_deg, "pose-graph edge weight");
  add.Add("sigma_translation_m", &options->sigma_translation_m, "pose-graph edge weight");
}

int RunPoseInitializer(int argc, char** argv) {
  std::string dataset_path;
  PoseInitializerPaths paths;
  PoseInitializerOptions initializer;
  colmap::OptionManager options;
  options.AddDatabaseOptions();
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddDefaultOption("registration_path",
                           &paths.registration_path,
                           "lidar_registrator's output (pairs.txt); empty: no LiDAR edges");
  options.AddRequiredOption("output_path", &paths.output_path);
  options.AddDefaultOption("depth_path",
                           &paths.depth_path,
                           "stereo_depth's output: cam_from_lidar refined by aligning the stereo "
                           "depth with the LiDAR; empty: not used");
  options.AddDefaultOption("input_path",
                           &paths.input_path,
                           "existing COLMAP model(s) of the same database: a model folder (.bin "
                           "or .txt) or colmap mapper's parent folder (sparse/0, sparse/1, ...); "
                           "rescaled to metres, joined and completed through the LiDAR edges");
  AddPoseInitializerOptions("", &options, &initializer);
  options.Parse(argc, argv);
  THROW_CHECK(initializer.Check());  // before any file is read
  paths.database_path = *options.database_path;
  // The registrator's de-skewed, static clouds, as in the pipeline: raw sweeps are smeared by the
  // platform's motion, which biases the stereo-LiDAR alignment.
  RunPoseInitializerStep(
      WithRegistratorClouds(ReadStationDataset(dataset_path), paths.registration_path),
      paths,
      initializer);
  return EXIT_SUCCESS;
}

namespace {

// The options of `pipeline`: its own, and every step's under the step's section.
struct PipelineOptions {
  std::string dataset_path;
  std::string workspace_path;
  bool overwrite = false;
  std::string mode = "joint";
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
  // Import.matcher auto: COLMAP's exhaustive matcher up to this many stations; beyond, the spatial
  // matcher on the LiDAR registration's station positions (each image with its
  // SpatialMatching.max_num_neighbors nearest), so that image pairs grow as N, not N^2.
  int max_exhaustive_stations = 16;
};

void AddPipelineOptions(colmap::OptionManager* manager, PipelineOptions* options) {
  manager->AddRequiredOption("dataset_path", &options->dataset_path);
  manager->AddRequiredOption("workspace_path", &options->workspace_path);
  manager->AddDefaultOption("overwrite", &options->overwrite, "rerun finished steps");
  manager->AddDefaultOption(
      "mode",
      &options->mode,
      "joint | precalibrated | stereo_only (stereo_only also fuses unrefined stereo)");
  // At 3 MP COLMAP's 8192 SIFT features (more with their second orientations) make matching the
  // import's cost; with 4096 the LiDAR, not the feature count, still sets the accuracy of
  // cam_from_lidar (docs/benchmarks/pipeline.md). Images of up to 1 MP rarely have more.
  manager->sift_extraction->max_num_features = 4096;
  options->import.matcher = "auto";
  options->import.import.spatial_matching.max_num_neighbors = 12;
  AddImportStepOptions("Import.", manager, &options->import);
  manager->AddDefaultOption(
      "Import.max_exhaustive_stations",
      &options->max_exhaustive_stations,
      "Import.matcher auto: exhaustive matching up to this many stations, spatial beyond");
  AddStereoDepthOptions("StereoDepth.", manager, &options->stereo);
  AddDepthPriorOptions("DepthPrior.", manager, &options->depth_prior);
  // All pairs grow as N^2: the pipeline registers each station with its 4 most similar ones.
  options->registrator.max_neighbors = 4;
  AddLidarRegistratorOptions("LidarRegistrator.", manager, &options->registrator);
  AddPoseInitializerOptions("PoseInitializer.", manager, &options->initializer);
  AddJointAdjusterOptions("JointAdjuster.", manager, &options->joint);
  AddDensifierOptions("Densifier.", manager, &options->densifier);
  AddModelEvaluationOptions("EvaluateModel.", manager, &options->evaluation);
  AddFrameSelectionOptions("FrameSelection.", manager, &options->selection);
}

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

// The steps in order, on the workspace layout (WorkspacePaths); the evaluation steps only when the
// dataset has ground truth.
std::vector<PipelineStep> PipelineSteps(const StationDataset& dataset,
                                        const PipelineOptions& options) {
  const WorkspacePaths paths(options.workspace_path);
  const std::string &database = paths.database, &stereo = paths.stereo, &lidar = paths.lidar,
                    &initial = paths.initial, &joint = paths.joint, &dense = paths.dense;
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
  const bool lidar_first = options.import.matcher == "spatial" || select;
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
  std::vector<PipelineStep> back_end = {
      {"pose_initializer",
       [=] {
         RunPoseInitializerStep(WithRegistratorClouds(camera_dataset(), lidar),
                                {database, registration, "", initial, stereo_rig ? stereo : ""},
                                options.initializer);
       }},
      {"joint_adjuster",
       [=] {
         RunJointAdjusterStep(WithRegistratorClouds(camera_dataset(), lidar),
                              {database, initial, "", joint},
                              options.joint);
       }},
      {"densifier",
       [=] {
         RunDensifierStep(WithRegistratorClouds(camera_dataset(), lidar),
                          {joint, "", stereo_rig ? stereo : "", dense},
                          options.densifier);
       }},
  };
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
  if (pipeline->import.matcher != "spatial" || !pipeline->import.lidar_registration_path.empty()) {
    return;
  }
  const WorkspacePaths paths(pipeline->workspace_path);
  pipeline->import.lidar_registration_path =
      SelectsFrames(dataset, *pipeline) ? paths.selected : paths.lidar;
}

}  // namespace

// Import.matcher auto (see PipelineOptions::max_exhaustive_stations).
void ResolveAutoMatcher(size_t num_stations, PipelineOptions* pipeline) {
  std::string& matcher = pipeline->import.matcher;
  if (matcher != "auto") return;
  const bool exhaustive = num_stations <= static_cast<size_t>(pipeline->max_exhaustive_stations);
  matcher = exhaustive ? "exhaustive" : "spatial";
  std::cout << "Import.matcher auto: " << num_stations << " stations, "
            << (exhaustive ? "exhaustive matching"
                           : "spatial matching (each image with its " +
                                 std::to_string(
                                     pipeline->import.import.spatial_matching.max_num_neighbors) +
                                 " nearest stations of the LiDAR registration)")
            << std::endl;
}

int RunPipeline(int argc, char** argv) {
  PipelineOptions pipeline;
  colmap::OptionManager manager;
  AddPipelineOptions(&manager, &pipeline);
  RefuseRemovedJointAdjusterOptions(argc, argv, "JointAdjuster.");
  manager.Parse(argc, argv);
  TakeColmapImportOptions(manager, &pipeline.import);
  pipeline.joint.mode = pipeline.mode;
  if (pipeline.mode == "stereo_only") pipeline.densifier.refine_with_lidar = false;
  // Every step's options are checked before the first step runs (the import's once its matcher is
  // chosen for the dataset's size).
  THROW_CHECK(pipeline.stereo.Check());
  THROW_CHECK(pipeline.depth_prior.Check());
  THROW_CHECK(pipeline.registrator.Check());
  THROW_CHECK(pipeline.initializer.Check());
  THROW_CHECK(pipeline.joint.Check());
  THROW_CHECK(pipeline.densifier.Check());
  ThrowUnlessValid(pipeline.selection, "FrameSelection");
  const StationDataset dataset = ReadStationDataset(pipeline.dataset_path);
  ResolveAutoMatcher(dataset.stations.size(), &pipeline);
  SetSpatialMatchingRegistration(dataset, &pipeline);
  THROW_CHECK(pipeline.import.Check());
  if (!dataset.rig.IsStereo() && pipeline.mode == "stereo_only") {
    throw std::invalid_argument("--mode stereo_only needs a stereo rig; " + dataset.root +
                                "/rig.json has one camera");
  }
  if (dataset.rig.lidar_sweep && !pipeline.registrator.deskew_sweeps) {
    // rig.json says the clouds are sweeps of a moving platform (import_kitti writes it).
    pipeline.registrator.deskew_sweeps = true;
    pipeline.registrator.sweep_timing.start_azimuth_deg =
        dataset.rig.lidar_sweep->start_azimuth_deg;
    pipeline.registrator.sweep_timing.counter_clockwise =
        dataset.rig.lidar_sweep->counter_clockwise;
    std::cout << dataset.root
              << "/rig.json: the clouds are sweeps of a moving platform (lidar.sweep): "
                 "lidar_registrator de-skews them"
              << std::endl;
  }
  pipeline.registrator.station_times = dataset.frame_times;
  pipeline.registrator.moving_platform = dataset.rig.IsMovingPlatform();
  if (!dataset.sweep_times.empty()) {
    pipeline.registrator.sweep_clock = SweepClock(dataset);
    std::cout << dataset.root << "/sweep_times.txt times the sweeps" << std::endl;
  }
  const fs::path ws(pipeline.workspace_path);
  const WorkspaceLock lock(pipeline.workspace_path);
  fs::create_directories(ws / "steps");
  fs::create_directories(ws / "sparse");
  RunSteps(PipelineSteps(dataset, pipeline), ws, pipeline.overwrite);
  std::cout << "  model: " << (ws / "sparse" / "joint").string()
            << " (cam_from_lidar.txt, report.json)\n"
            << "  dense: " << (ws / "dense").string()
            << " (fused.ply, lidar_map.ply, COLMAP dense workspace)" << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
