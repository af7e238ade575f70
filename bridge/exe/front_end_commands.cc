// The front end's steps and commands: import_dataset, stereo_depth, depth_prior_extractor.
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/logging.h"

#include "colmap/feature/pairing.h"

#include <chrono>
#include <iomanip>
#include <iostream>

namespace colmap_lidar {
namespace {

// --matcher exhaustive | sequential | spatial, and auto with `choose_matcher`.
void AddMatcherOption(const std::string& name,
                      CommandOptions* manager,
                      ImageMatcher* matcher,
                      bool* choose_matcher) {
  const std::string help =
      "sequential: frames of a moving platform, by name; spatial: stations near in "
      "--lidar_registration_path";
  if (choose_matcher == nullptr) {
    manager->AddChoiceOption(name, matcher, kImageMatcherNames, help);
    return;
  }
  manager->AddParsedOption(
      name,
      *choose_matcher ? "auto" : ImageMatcherName(*matcher),
      [=](const std::string& text) {
        *choose_matcher = text == "auto";
        if (!*choose_matcher) *matcher = ChoiceFromName(kImageMatcherNames, text, "--" + name);
      },
      "auto, exhaustive, sequential or spatial (" + help +
          "; auto: exhaustive up to Import.max_exhaustive_stations, spatial beyond)");
}

}  // namespace

void AddImportStepOptions(const std::string& prefix,
                          CommandOptions* manager,
                          ImportStepOptions* options,
                          bool* choose_matcher) {
  // GPU SIFT needs CUDA or an OpenGL context; a headless build has neither.
  manager->sift_extraction->use_gpu = false;
  manager->sift_matching->use_gpu = false;
  manager->AddExtractionOptions();
  manager->AddExhaustiveMatchingOptions();
  manager->AddSequentialMatchingOptions();
  *manager->spatial_matching = options->import.spatial_matching;
  manager->AddSpatialMatchingOptions();
  PrefixedOptions add(manager, prefix);
  AddMatcherOption(prefix + "matcher", manager, &options->import.matcher, choose_matcher);
  add.Add("lidar_registration_path",
          &options->lidar_registration_path,
          "lidar_registrator's output folder, for --matcher spatial");
  add.Add("image_name_format",
          &options->import.image_name_format,
          "database name of each station's image, e.g. {station}.png for a database made by "
          "colmap feature_extractor (its images are reused); empty: left/{station}.png");
  add.Add("image_path",
          &options->import.image_path,
          "folder of the images named by --image_name_format; empty: DATASET/images");
}

void TakeColmapImportOptions(const CommandOptions& manager, ImportStepOptions* options) {
  options->import.sift_extraction = *manager.sift_extraction;
  options->import.sift_matching = *manager.sift_matching;
  options->import.two_view_geometry = *manager.two_view_geometry;
  options->import.exhaustive_matching = *manager.exhaustive_matching;
  options->import.sequential_matching = *manager.sequential_matching;
  options->import.spatial_matching = *manager.spatial_matching;
}

int RunImportDataset(int argc, char** argv) {
  std::string dataset_path;
  ImportStepOptions import;
  CommandOptions options;
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddDatabaseOptions();
  AddImportStepOptions("", &options, &import);
  options.Parse(argc, argv);
  TakeColmapImportOptions(options, &import);
  THROW_CHECK(import.Check());  // before any file is read
  RunImportStep(ReadStationDataset(dataset_path), *options.database_path, import);
  return EXIT_SUCCESS;
}

void AddStereoDepthOptions(const std::string& prefix,
                           CommandOptions* manager,
                           StereoDepthOptions* options) {
  PrefixedOptions add(manager, prefix);
  add.AddChoice("mode", &options->mode, kSgbmModeNames, "OpenCV StereoSGBM's mode");
  add.Add("min_depth_m", &options->min_depth_m);
  add.Add("max_depth_m", &options->max_depth_m);
  add.Add("vertically_symmetric", &options->vertically_symmetric);
  add.Add("block_size", &options->block_size);
  add.Add("p1_factor", &options->p1_factor);
  add.Add("p2_factor", &options->p2_factor);
  add.Add("uniqueness_ratio", &options->uniqueness_ratio);
  add.Add("pre_filter_cap", &options->pre_filter_cap);
  add.Add("speckle_window_size", &options->speckle_window_size);
  add.Add("speckle_range_px", &options->speckle_range_px);
  add.Add("max_left_right_diff_px", &options->max_left_right_diff_px);
  add.Add("mirrored_left_right_check", &options->mirrored_left_right_check);
  add.Add("num_threads", &options->num_threads);
}

int RunStereoDepth(int argc, char** argv) {
  std::string dataset_path;
  std::string output_path;
  StereoDepthOptions stereo;
  CommandOptions options;
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddRequiredOption("output_path", &output_path);
  AddStereoDepthOptions("", &options, &stereo);
  options.Parse(argc, argv);
  THROW_CHECK(stereo.Check());  // before any file is read
  RunStereoDepthStep(ReadStationDataset(dataset_path), output_path, stereo);
  return EXIT_SUCCESS;
}

void AddDepthPriorOptions(const std::string& prefix,
                          CommandOptions* manager,
                          DepthPriorOptions* options) {
  PrefixedOptions add(manager, prefix);
  add.Add("max_radius_px", &options->max_radius_px);
  add.Add("sigma_pixels", &options->sigma_pixels, "sigma_p of sigma_d = d^2/(b f) sigma_p");
  add.Add("max_relative_jump", &options->max_relative_jump);
}

int RunDepthPriorExtractor(int argc, char** argv) {
  std::string depth_path;
  DepthPriorOptions prior_options;
  CommandOptions options;
  options.AddDatabaseOptions();
  options.AddRequiredOption("depth_path", &depth_path);
  AddDepthPriorOptions("", &options, &prior_options);
  options.Parse(argc, argv);
  RunDepthPriorStep(*options.database_path, depth_path, prior_options);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
