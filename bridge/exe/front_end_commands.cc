// The front end's commands: import_dataset, stereo_depth, depth_prior_extractor.
#include "bridge/exe/commands.h"
#include "bridge/lidar_registration_files.h"
#include "colmap_ext/dataset_import.h"
#include "colmap_ext/depth_prior_extractor.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "colmap_ext/stereo_depth.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/feature/pairing.h"

#include <chrono>
#include <iomanip>
#include <iostream>

namespace colmap_lidar {

int RunImportDataset(int argc, char** argv) {
  std::string dataset_path;
  colmap::OptionManager options;
  // GPU SIFT needs CUDA or an OpenGL context; a headless build has neither.
  options.sift_extraction->use_gpu = false;
  options.sift_matching->use_gpu = false;
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddDatabaseOptions();
  options.AddExtractionOptions();
  options.AddExhaustiveMatchingOptions();
  options.AddSequentialMatchingOptions();
  DatasetImportOptions import_options;
  *options.spatial_matching = import_options.spatial_matching;
  options.AddSpatialMatchingOptions();
  std::string registration_path;
  options.AddDefaultOption(
      "matcher",
      &import_options.matcher,
      "exhaustive | sequential (frames of a moving platform, by name) | spatial "
      "(stations near in --lidar_registration_path)");
  options.AddDefaultOption("lidar_registration_path",
                           &registration_path,
                           "lidar_registrator's output folder, for --matcher spatial");
  options.Parse(argc, argv);

  const auto start = std::chrono::steady_clock::now();
  const StationDataset dataset = ReadStationDataset(dataset_path);
  import_options.sift_extraction = *options.sift_extraction;
  import_options.sift_matching = *options.sift_matching;
  import_options.two_view_geometry = *options.two_view_geometry;
  import_options.exhaustive_matching = *options.exhaustive_matching;
  import_options.sequential_matching = *options.sequential_matching;
  import_options.spatial_matching = *options.spatial_matching;
  if (import_options.matcher == "spatial") {
    THROW_CHECK(!registration_path.empty()) << "--matcher spatial needs --lidar_registration_path";
    import_options.station_positions = StationCameraPositions(
        registration_path, dataset.rig.cam_from_lidar_guess.value_or(colmap::Rigid3d()));
  }
  const DatasetImportSummary summary =
      ImportDataset(dataset, *options.database_path, import_options);
  std::cout << "Imported " << dataset.root << " into " << *options.database_path << ": "
            << summary.num_images << " station images (" << summary.num_new_images
            << " new), camera " << summary.camera_id << ", " << summary.num_verified_pairs
            << " verified image pairs (" << std::fixed << std::setprecision(0)
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s)" << std::endl;
  return EXIT_SUCCESS;
}

int RunStereoDepth(int argc, char** argv) {
  std::string dataset_path;
  std::string output_path;
  StereoDepthOptions stereo;
  colmap::OptionManager options(/*add_project_options=*/true);
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddRequiredOption("output_path", &output_path);
  options.AddDefaultOption("mode", &stereo.mode, "sgbm | hh | 3way | hh4");
  options.AddDefaultOption("min_depth_m", &stereo.min_depth_m);
  options.AddDefaultOption("max_depth_m", &stereo.max_depth_m);
  options.AddDefaultOption("vertically_symmetric", &stereo.vertically_symmetric);
  options.AddDefaultOption("block_size", &stereo.block_size);
  options.AddDefaultOption("p1_factor", &stereo.p1_factor);
  options.AddDefaultOption("p2_factor", &stereo.p2_factor);
  options.AddDefaultOption("uniqueness_ratio", &stereo.uniqueness_ratio);
  options.AddDefaultOption("pre_filter_cap", &stereo.pre_filter_cap);
  options.AddDefaultOption("speckle_window_size", &stereo.speckle_window_size);
  options.AddDefaultOption("speckle_range_px", &stereo.speckle_range_px);
  options.AddDefaultOption("max_left_right_diff_px", &stereo.max_left_right_diff_px);
  options.AddDefaultOption("num_threads", &stereo.num_threads);
  options.Parse(argc, argv);
  THROW_CHECK(stereo.Check());
  const StationDataset dataset = ReadStationDataset(dataset_path);
  const auto start = std::chrono::steady_clock::now();
  ComputeDatasetStereoDepth(dataset, output_path, stereo);
  std::cout << "Depth maps of " << dataset.stations.size() << " stations written to " << output_path
            << " (" << std::fixed << std::setprecision(0)
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s)" << std::endl;
  return EXIT_SUCCESS;
}

int RunDepthPriorExtractor(int argc, char** argv) {
  std::string depth_path;
  DepthPriorOptions prior_options;
  colmap::OptionManager options;
  options.AddDatabaseOptions();
  options.AddRequiredOption("depth_path", &depth_path);
  options.AddDefaultOption("max_radius_px", &prior_options.max_radius_px);
  options.AddDefaultOption(
      "sigma_pixels", &prior_options.sigma_pixels, "sigma_p of sigma_d = d^2/(b f) sigma_p");
  options.AddDefaultOption("max_relative_jump", &prior_options.max_relative_jump);
  options.Parse(argc, argv);
  THROW_CHECK(prior_options.Check());
  const std::vector<ImageDepthPriorCount> counts =
      ExtractDatabaseDepthPriors(*options.database_path, depth_path, prior_options);
  size_t num_keypoints = 0, num_priors = 0, num_without_map = 0;
  for (const ImageDepthPriorCount& count : counts) {
    num_keypoints += count.num_keypoints;
    num_priors += count.num_priors;
    if (!count.has_depth_map) ++num_without_map;
  }
  std::cout << "Depth priors: " << num_priors << " of " << num_keypoints << " keypoints ("
            << std::fixed << std::setprecision(1)
            << 100.0 * num_priors / std::max<size_t>(1, num_keypoints) << " %) in " << counts.size()
            << " images";
  if (num_without_map > 0) {
    std::cout << "; " << num_without_map << " images had no depth map";
  }
  std::cout << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
