// Imports a station dataset into a COLMAP database: the left camera from rig.json (its intrinsics are
// kept: prior_focal_length = 1, never re-estimated from EXIF), one image per station named
// "left/<station>.png", COLMAP's own SIFT extraction and matching (exhaustive, sequential or spatial) with
// geometric verification
// (libcolmap's controllers, so every --SiftExtraction.* / --SiftMatching.* / --TwoViewGeometry.* option
// is COLMAP's), plus colmap-lidar's rig and lidar_frames rows.
//
// Atomic and idempotent: the work happens on a copy (DATABASE.import-partial) that is copied back into
// DATABASE in one transaction (SQLite's backup API) only when everything succeeded; a failure leaves
// DATABASE byte-for-byte unchanged. Re-running on an imported
// database adds nothing (COLMAP skips images with features and pairs already matched; our rows are
// upserts); stations added to the dataset since are added.
#pragma once

#include "colmap_ext/station_dataset.h"
#include "lidar/util/named_choice.h"

#include "colmap/estimators/two_view_geometry.h"
#include "colmap/feature/pairing.h"
#include "colmap/feature/sift.h"

#include <Eigen/Core>

#include <map>
#include <string>

namespace colmap_lidar {

colmap::SpatialMatchingOptions LidarSpatialMatchingOptions();

// How the imported images are paired for matching: every pair; each image with its successors by
// name (frames of a moving platform); each image with the images whose stations are near.
enum class ImageMatcher { kExhaustive, kSequential, kSpatial };
inline constexpr NamedChoices<ImageMatcher, 3> kImageMatcherNames = {
    {{"exhaustive", ImageMatcher::kExhaustive},
     {"sequential", ImageMatcher::kSequential},
     {"spatial", ImageMatcher::kSpatial}}};
const char* ImageMatcherName(ImageMatcher matcher);

struct DatasetImportOptions {
  colmap::SiftExtractionOptions sift_extraction;
  colmap::SiftMatchingOptions sift_matching;
  colmap::TwoViewGeometryOptions two_view_geometry;
  // Sequential: SequentialMatchingOptions::overlap successors; spatial: COLMAP's spatial matcher on
  // pose priors written from `station_positions`.
  ImageMatcher matcher = ImageMatcher::kExhaustive;
  colmap::ExhaustiveMatchingOptions exhaustive_matching;
  colmap::SequentialMatchingOptions sequential_matching;
  // COLMAP's defaults except ignore_z = false (LiDAR positions, unlike GPS, have a good z).
  colmap::SpatialMatchingOptions spatial_matching = LidarSpatialMatchingOptions();
  // kSpatial: the position of each station's camera in one world frame, by station name (e.g. from
  // lidar_registrator's lidar_poses.txt). Stations without one get no pose prior; they are matched
  // with every other image instead.
  std::map<std::string, Eigen::Vector3d> station_positions;
  // The database name of each station's image, "{station}" standing for the station's name: e.g.
  // "{station}.png" or "cam0/{station}.jpg" for a database made by the user's own `colmap
  // feature_extractor`, whose images (keypoints, matches) are then reused, never added twice. The
  // file name must be "{station}" plus an extension (the other steps find a station's image by the
  // stem of its name). Empty: this tool's layout, "left/{station}.png".
  std::string image_name_format;
  // Where images named by image_name_format that are not yet in the database are read; empty:
  // DATASET/images.
  std::string image_path;

  bool Check() const;
  // The database name of station `station`'s image.
  std::string ImageName(const StationDataset& dataset, size_t station) const;
};

struct DatasetImportSummary {
  colmap::camera_t camera_id = colmap::kInvalidCameraId;
  size_t num_images = 0;      // station images in the database afterwards
  size_t num_new_images = 0;  // added by this run
  size_t num_verified_pairs = 0;
};

// Every station's left and right image can be read and has the size of its rig.json camera; throws
// std::runtime_error naming the station and the file otherwise.
void CheckStationImages(const StationDataset& dataset);

DatasetImportSummary ImportDataset(const StationDataset& dataset,
                                   const std::string& database_path,
                                   const DatasetImportOptions& options);

}  // namespace colmap_lidar
