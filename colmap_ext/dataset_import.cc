#include "colmap_ext/dataset_import.h"

#include "colmap_ext/extension_database.h"
#include "colmap_ext/logging.h"

#include "colmap/controllers/feature_extraction.h"
#include "colmap/controllers/feature_matching.h"
#include "colmap/controllers/image_reader.h"
#include "colmap/geometry/gps.h"
#include "colmap/scene/database.h"

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <iostream>
#include <sstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

void CheckImage(const std::string& station,
                const std::string& side,
                const std::string& path,
                const colmap::Camera& camera) {
  const cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (image.empty()) {
    throw std::runtime_error("station " + station + ": cannot read the " + side + " image " + path);
  }
  if (static_cast<size_t>(image.cols) != camera.width ||
      static_cast<size_t>(image.rows) != camera.height) {
    std::ostringstream message;
    message << "station " << station << ": the " << side << " image " << path << " is "
            << image.cols << "x" << image.rows << " but rig.json's " << side << " camera is "
            << camera.width << "x" << camera.height;
    throw std::runtime_error(message.str());
  }
}

bool SameIntrinsics(const colmap::Camera& a, const colmap::Camera& b) {
  if (a.model_id != b.model_id || a.width != b.width || a.height != b.height ||
      a.params.size() != b.params.size()) {
    return false;
  }
  for (size_t i = 0; i < a.params.size(); ++i) {
    if (std::abs(a.params[i] - b.params[i]) > 1e-9 * (1 + std::abs(b.params[i]))) {
      return false;
    }
  }
  return true;
}

// The left camera: the one our rig row names if the database has one (it must match rig.json); for a
// monocular rig (no rig row) an existing camera with rig.json's intrinsics (a second import); else a
// new camera with rig.json's intrinsics.
colmap::camera_t LeftCameraId(const StationDataset& dataset,
                              colmap::Database* database,
                              ExtensionDatabase* extension) {
  const std::optional<StereoRig> rig = extension->ReadRig();
  if (rig && database->ExistsCamera(rig->left_camera_id)) {
    const colmap::Camera camera = database->ReadCamera(rig->left_camera_id);
    if (!SameIntrinsics(camera, dataset.rig.left)) {
      throw std::runtime_error("the database already holds a rig whose left camera (camera_id " +
                               std::to_string(rig->left_camera_id) + ", " + camera.ModelName() +
                               " " + camera.ParamsToString() +
                               ") differs from the left camera in " + dataset.root +
                               "/rig.json; import into a new database");
    }
    return rig->left_camera_id;
  }
  if (!dataset.rig.IsStereo()) {
    for (const colmap::Camera& existing : database->ReadAllCameras()) {
      if (SameIntrinsics(existing, dataset.rig.left)) return existing.camera_id;
    }
  }
  colmap::Camera camera = dataset.rig.left;
  camera.has_prior_focal_length = true;
  return database->WriteCamera(camera);
}

// The image id of each station's left image after COLMAP's extraction; throws naming the station
// when COLMAP did not import it, it has another camera, or it has no features.
std::vector<colmap::image_t> ImportedImageIds(const StationDataset& dataset,
                                              const std::vector<std::string>& names,
                                              colmap::camera_t camera_id,
                                              const std::string& database_path) {
  std::vector<colmap::image_t> image_ids;
  colmap::Database database(database_path);
  for (size_t i = 0; i < names.size(); ++i) {
    if (!database.ExistsImageWithName(names[i])) {
      throw std::runtime_error("station " + dataset.stations[i] + ": COLMAP did not import " +
                               dataset.LeftImagePath(i));
    }
    const colmap::Image image = database.ReadImageWithName(names[i]);
    if (image.CameraId() != camera_id) {
      throw std::runtime_error("station " + dataset.stations[i] + ": image " + names[i] +
                               " already exists in the database with another camera (" +
                               std::to_string(image.CameraId()) + ")");
    }
    if (!database.ExistsKeypoints(image.ImageId())) {
      throw std::runtime_error("station " + dataset.stations[i] +
                               ": COLMAP extracted no features from " + dataset.LeftImagePath(i));
    }
    image_ids.push_back(image.ImageId());
  }
  return image_ids;
}

// Pose priors (COLMAP's pose_priors table, cartesian) from the stations' positions, for the spatial
// matcher; an image that has one already keeps it.
void WritePosePriors(const StationDataset& dataset,
                     const std::vector<colmap::image_t>& image_ids,
                     const DatasetImportOptions& options,
                     const std::string& database_path) {
  const colmap::Database database(database_path);
  size_t written = 0, kept = 0;
  for (size_t i = 0; i < image_ids.size(); ++i) {
    const auto position = options.station_positions.find(dataset.stations[i]);
    if (position == options.station_positions.end()) continue;
    if (database.ExistsPosePrior(image_ids[i])) {
      ++kept;
      continue;
    }
    database.WritePosePrior(
        image_ids[i],
        colmap::PosePrior(position->second, colmap::PosePrior::CoordinateSystem::CARTESIAN));
    ++written;
  }
  std::cout << "Pose priors for spatial matching: " << written << " written, " << kept << " kept, "
            << image_ids.size() - written - kept << " stations without a position" << std::endl;
}

// COLMAP's exhaustive, sequential or spatial matcher on the database.
void MatchFeatures(const DatasetImportOptions& options, const std::string& database_path) {
  std::cout << "COLMAP " << options.matcher << " matching" << std::endl;
  std::unique_ptr<colmap::Thread> matcher;
  if (options.matcher == "sequential") {
    matcher = colmap::CreateSequentialFeatureMatcher(options.sequential_matching,
                                                     options.sift_matching,
                                                     options.two_view_geometry,
                                                     database_path);
  } else if (options.matcher == "spatial") {
    matcher = colmap::CreateSpatialFeatureMatcher(
        options.spatial_matching, options.sift_matching, options.two_view_geometry, database_path);
  } else {
    matcher = colmap::CreateExhaustiveFeatureMatcher(options.exhaustive_matching,
                                                     options.sift_matching,
                                                     options.two_view_geometry,
                                                     database_path);
  }
  matcher->Start();
  matcher->Wait();
}

// Our tables: the stereo rig and each station's LiDAR frame.
void WriteRigAndLidarFrames(const StationDataset& dataset,
                            colmap::camera_t camera_id,
                            const std::vector<colmap::image_t>& image_ids,
                            const std::string& database_path) {
  ExtensionDatabase extension(database_path);
  if (dataset.rig.IsStereo()) {
    StereoRig rig;
    rig.left_camera_id = camera_id;
    rig.right_camera = *dataset.rig.right;
    rig.right_from_left = dataset.rig.right_from_left;
    extension.WriteRig(rig);
  }
  for (size_t i = 0; i < image_ids.size(); ++i) {
    LidarFrame frame;
    frame.image_id = image_ids[i];
    frame.path = fs::relative(dataset.cloud_paths[i], dataset.root).generic_string();
    frame.cam_from_lidar_guess = dataset.rig.cam_from_lidar_guess;
    extension.WriteLidarFrame(frame);
  }
}

}  // namespace

colmap::SpatialMatchingOptions LidarSpatialMatchingOptions() {
  colmap::SpatialMatchingOptions options;
  options.ignore_z = false;
  return options;
}

bool DatasetImportOptions::Check() const {
  CHECK_OPTION(matcher == "exhaustive" || matcher == "sequential" || matcher == "spatial");
  CHECK_OPTION(exhaustive_matching.Check());
  CHECK_OPTION(sequential_matching.Check());
  CHECK_OPTION(spatial_matching.Check());
  return true;
}

void CheckStationImages(const StationDataset& dataset) {
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    CheckImage(dataset.stations[i], "left", dataset.LeftImagePath(i), dataset.rig.left);
    if (dataset.rig.IsStereo()) {
      CheckImage(dataset.stations[i], "right", dataset.RightImagePath(i), *dataset.rig.right);
    }
  }
}

DatasetImportSummary ImportDataset(const StationDataset& dataset,
                                   const std::string& database_path,
                                   const DatasetImportOptions& options) {
  THROW_CHECK(options.sift_extraction.Check());
  THROW_CHECK(options.sift_matching.Check());
  THROW_CHECK(options.two_view_geometry.Check());
  THROW_CHECK(options.Check());
  THROW_CHECK(options.matcher != "spatial" || !options.station_positions.empty())
      << "the spatial matcher needs station positions (none came from the LiDAR registration)";
  THROW_CHECK(!dataset.stations.empty()) << "no stations in " << dataset.root;
  std::cout << "Checking " << dataset.stations.size()
            << (dataset.rig.IsStereo() ? " stereo pairs of " : " images (monocular rig) of ")
            << dataset.root << std::endl;
  CheckStationImages(dataset);

  const std::string partial = database_path + ".import-partial";
  const auto remove_partial = [&partial]() {
    std::error_code ignored;
    for (const char* suffix : {"", "-journal", "-wal", "-shm"}) {
      fs::remove(partial + suffix, ignored);
    }
  };
  remove_partial();
  if (fs::exists(database_path)) {
    // Rejects a non-COLMAP file before anything is written; the copy is a consistent snapshot.
    { ExtensionDatabase check(database_path, ExtensionDatabase::Mode::kReadOnly); }
    CopySqliteDatabase(database_path, partial);
  }
  try {
    DatasetImportSummary summary;
    std::vector<std::string> names;
    for (size_t i = 0; i < dataset.stations.size(); ++i) {
      names.push_back(dataset.LeftImageName(i));
    }
    {
      colmap::Database database(partial);  // creates COLMAP's tables if new
      ExtensionDatabase extension(partial);
      summary.camera_id = LeftCameraId(dataset, &database, &extension);
      for (const std::string& name : names) {
        if (!database.ExistsImageWithName(name)) ++summary.num_new_images;
      }
    }

    colmap::ImageReaderOptions reader_options;
    reader_options.database_path = partial;
    reader_options.image_path = (fs::path(dataset.root) / "images").string();
    reader_options.image_list = names;
    reader_options.existing_camera_id = static_cast<int>(summary.camera_id);
    std::cout << "COLMAP SIFT extraction (" << summary.num_new_images << " new images)"
              << std::endl;
    auto extractor =
        colmap::CreateFeatureExtractorController(reader_options, options.sift_extraction);
    extractor->Start();
    extractor->Wait();
    extractor.reset();  // closes its database connection

    const std::vector<colmap::image_t> image_ids =
        ImportedImageIds(dataset, names, summary.camera_id, partial);

    if (options.matcher == "spatial") WritePosePriors(dataset, image_ids, options, partial);
    MatchFeatures(options, partial);

    WriteRigAndLidarFrames(dataset, summary.camera_id, image_ids, partial);
    {
      const colmap::Database database(partial);
      summary.num_images = names.size();
      summary.num_verified_pairs = database.NumVerifiedImagePairs();
    }
    // Into the user's database in one transaction (SQLite's backup API: correct with COLMAP's WAL
    // journal, unlike a rename, and it waits for or reports other writers).
    CopySqliteDatabase(partial, database_path);
    remove_partial();
    return summary;
  } catch (...) {
    remove_partial();
    throw;
  }
}

}  // namespace colmap_lidar
