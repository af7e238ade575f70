#include "bridge/pipeline/front_end_steps.h"

#include "bridge/initialization/lidar_registration_files.h"
#include "colmap_ext/elapsed.h"
#include "colmap_ext/logging.h"
#include "lidar/util/check_option.h"

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>

namespace colmap_lidar {

bool ImportStepOptions::Check() const {
  CHECK_OPTION(import.Check());
  CHECK_OPTION(import.matcher != ImageMatcher::kSpatial || !lidar_registration_path.empty());
  return true;
}

void RunImportStep(const StationDataset& dataset,
                   const std::string& database_path,
                   ImportStepOptions options) {
  const auto start = std::chrono::steady_clock::now();
  THROW_CHECK(options.Check());
  if (options.import.matcher == ImageMatcher::kSpatial) {
    options.import.station_positions =
        StationCameraPositions(options.lidar_registration_path,
                               dataset.rig.cam_from_lidar_guess.value_or(colmap::Rigid3d()));
  }
  const DatasetImportSummary summary = ImportDataset(dataset, database_path, options.import);
  std::cout << "Imported " << dataset.root << " into " << database_path << ": "
            << summary.num_images << " station images (" << summary.num_new_images
            << " new), camera " << summary.camera_id << ", " << summary.num_verified_pairs
            << " verified image pairs (" << std::fixed << std::setprecision(0)
            << SecondsSince(start) << " s)" << std::endl;
}

void RunStereoDepthStep(const StationDataset& dataset,
                        const std::string& output_path,
                        const StereoDepthOptions& options) {
  THROW_CHECK(options.Check());
  const auto start = std::chrono::steady_clock::now();
  ComputeDatasetStereoDepth(dataset, output_path, options);
  std::cout << "Depth maps of " << dataset.stations.size() << " stations written to " << output_path
            << " (" << std::fixed << std::setprecision(0) << SecondsSince(start) << " s)"
            << std::endl;
}

void RunDepthPriorStep(const std::string& database_path,
                       const std::string& depth_path,
                       const DepthPriorOptions& options) {
  THROW_CHECK(options.Check());
  const std::vector<ImageDepthPriorCount> counts =
      ExtractDatabaseDepthPriors(database_path, depth_path, options);
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
}

}  // namespace colmap_lidar
