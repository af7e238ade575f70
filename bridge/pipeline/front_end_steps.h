// The front end's steps as library calls: COLMAP SIFT extraction and matching into the database
// with our rig and lidar_frames rows (import_dataset), SGM stereo depth maps of every station
// (stereo_depth) and the depth priors of the database's keypoints (depth_prior_extractor). Each
// prints what it did; errors are thrown.
#pragma once

#include "colmap_ext/dataset_import.h"
#include "colmap_ext/depth_prior_extractor.h"
#include "colmap_ext/station_dataset.h"
#include "colmap_ext/stereo_depth.h"

#include <string>

namespace colmap_lidar {

// import_dataset: COLMAP SIFT extraction and matching, our rig and lidar_frames rows.
struct ImportStepOptions {
  DatasetImportOptions import;
  // lidar_registrator's output folder, for the spatial matcher (import.matcher).
  std::string lidar_registration_path;

  bool Check() const;
};
void RunImportStep(const StationDataset& dataset,
                   const std::string& database_path,
                   ImportStepOptions options);

void RunStereoDepthStep(const StationDataset& dataset,
                        const std::string& output_path,
                        const StereoDepthOptions& options);

void RunDepthPriorStep(const std::string& database_path,
                       const std::string& depth_path,
                       const DepthPriorOptions& options);

}  // namespace colmap_lidar
