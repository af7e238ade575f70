// pose_initializer and pipeline: from raw stations to a metric sparse model with cam_from_lidar.
#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "bridge/initialization/pose_initializer.h"
#include "bridge/pipeline/pipeline_controller.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/util/check_option.h"

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <vector>

namespace colmap_lidar {
namespace fs = std::filesystem;

void AddPoseInitializerOptions(const std::string& prefix,
                               CommandOptions* manager,
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
  CommandOptions options;
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

void AddPipelineOptions(CommandOptions* manager, PipelineOptions* options) {
  manager->AddRequiredOption("dataset_path", &options->dataset_path);
  manager->AddRequiredOption("workspace_path", &options->workspace_path);
  manager->AddDefaultOption("overwrite", &options->overwrite, "rerun finished steps");
  manager->AddDefaultOption(
      "stop_after", &options->stop_after, "the last step to run (e.g. pose_initializer)");
  manager->AddChoiceOption(
      "mode", &options->mode, kJointModeNames, "stereo_only also fuses unrefined stereo");
  // The pipeline's own defaults (PipelineOptions()) for COLMAP's sections too.
  *manager->sift_extraction = options->import.import.sift_extraction;
  *manager->sift_matching = options->import.import.sift_matching;
  AddImportStepOptions("Import.", manager, &options->import, &options->choose_matcher);
  manager->AddDefaultOption(
      "Import.max_exhaustive_stations",
      &options->max_exhaustive_stations,
      "Import.matcher auto: exhaustive matching up to this many stations, spatial beyond");
  AddStereoDepthOptions("StereoDepth.", manager, &options->stereo);
  AddDepthPriorOptions("DepthPrior.", manager, &options->depth_prior);
  AddLidarRegistratorOptions("LidarRegistrator.", manager, &options->registrator);
  AddPoseInitializerOptions("PoseInitializer.", manager, &options->initializer);
  AddJointAdjusterOptions("JointAdjuster.", manager, &options->joint);
  AddDensifierOptions("Densifier.", manager, &options->densifier);
  AddModelEvaluationOptions("EvaluateModel.", manager, &options->evaluation);
  AddFrameSelectionOptions("FrameSelection.", manager, &options->selection);
}

}  // namespace

int RunPipeline(int argc, char** argv) {
  PipelineOptions pipeline;
  CommandOptions manager;
  AddPipelineOptions(&manager, &pipeline);
  RefuseRemovedJointAdjusterOptions(argc, argv, "JointAdjuster.");
  manager.Parse(argc, argv);
  TakeColmapImportOptions(manager, &pipeline.import);
  RunFullPipeline(pipeline);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
