#include "colmap_ext/dataset_import.h"

#include "colmap_ext/extension_database.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/pair_verification.h"
#include "colmap_ext/sift_matching.h"

#include "colmap/controllers/feature_extraction.h"
#include "colmap/controllers/image_reader.h"
#include "colmap/feature/pairing.h"
#include "colmap/geometry/gps.h"
#include "colmap/scene/database.h"

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

constexpr char kStationPlaceholder[] = "{station}";

using ImagePair = std::pair<colmap::image_t, colmap::image_t>;

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

// A database of the user's own (image_name_format given): the camera of the station images already in
// it, given rig.json's intrinsics if they differ (keypoints and matches are pixels and stay valid).
// Refused when the station images have several cameras or the camera also serves other images;
// std::nullopt when no station image is in the database yet.
std::optional<colmap::camera_t> ExistingStationCamera(const StationDataset& dataset,
                                                      const std::vector<std::string>& names,
                                                      colmap::Database* database) {
  std::set<colmap::camera_t> cameras;
  for (const std::string& name : names) {
    if (database->ExistsImageWithName(name)) {
      cameras.insert(database->ReadImageWithName(name).CameraId());
    }
  }
  if (cameras.empty()) return std::nullopt;
  if (cameras.size() > 1) {
    throw std::runtime_error("the stations' images in the database have " +
                             std::to_string(cameras.size()) +
                             " cameras, but a station dataset has one left camera (rig.json)");
  }
  const colmap::camera_t camera_id = *cameras.begin();
  const colmap::Camera camera = database->ReadCamera(camera_id);
  if (SameIntrinsics(camera, dataset.rig.left)) return camera_id;
  const std::set<std::string> station_names(names.begin(), names.end());
  for (const colmap::Image& image : database->ReadAllImages()) {
    if (image.CameraId() == camera_id && !station_names.count(image.Name())) {
      throw std::runtime_error("camera " + std::to_string(camera_id) +
                               " of the stations' images (" + camera.ModelName() + " " +
                               camera.ParamsToString() +
                               ") differs from rig.json's left camera and also serves image " +
                               image.Name() + "; import into a database of the stations only");
    }
  }
  std::cout << "Camera " << camera_id << " of the stations' images (" << camera.ModelName() << " "
            << camera.ParamsToString() << ") takes rig.json's calibration ("
            << dataset.rig.left.ModelName() << " " << dataset.rig.left.ParamsToString() << ")"
            << std::endl;
  colmap::Camera calibrated = dataset.rig.left;
  calibrated.camera_id = camera_id;
  calibrated.has_prior_focal_length = true;
  database->UpdateCamera(calibrated);
  return camera_id;
}

// Every station image not yet in the database must be readable under `image_path`.
void CheckNewImagesExist(const StationDataset& dataset,
                         const std::vector<std::string>& names,
                         const std::string& image_path,
                         const DatasetImportOptions& options,
                         const colmap::Database& database) {
  for (size_t i = 0; i < names.size(); ++i) {
    if (database.ExistsImageWithName(names[i])) continue;
    const fs::path path = fs::path(image_path) / names[i];
    if (!fs::is_regular_file(path)) {
      throw std::runtime_error(
          "station " + dataset.stations[i] + " has no image " + names[i] + " (image name format '" +
          (options.image_name_format.empty() ? "left/{station}.png" : options.image_name_format) +
          "'): not in the database, nor at " + path.string());
    }
  }
}

// Before extraction: every new image exists, the stations' camera is chosen, and the new images are
// written in station order (counted into `summary`); true if every station image is in the database
// with its features already.
bool PrepareCamera(const StationDataset& dataset,
                   const std::vector<std::string>& names,
                   const std::string& image_path,
                   const DatasetImportOptions& options,
                   const std::string& database_path,
                   DatasetImportSummary* summary) {
  colmap::Database database(database_path);  // creates COLMAP's tables if new
  ExtensionDatabase extension(database_path);
  CheckNewImagesExist(dataset, names, image_path, options, database);
  std::optional<colmap::camera_t> camera_id;
  if (!options.image_name_format.empty()) {
    camera_id = ExistingStationCamera(dataset, names, &database);
  }
  summary->camera_id = camera_id ? *camera_id : LeftCameraId(dataset, &database, &extension);
  bool all_extracted = true;
  for (const std::string& name : names) {
    if (!database.ExistsImageWithName(name)) {
      // COLMAP's extraction numbers new images in the order its threads finish them, and the
      // matcher's pair order follows the ids. Written here in station order, the images get the
      // same ids in every run; the extraction then fills in their features.
      colmap::Image image;
      image.SetName(name);
      image.SetCameraId(summary->camera_id);
      database.WriteImage(image);
      ++summary->num_new_images;
      all_extracted = false;
    } else if (!database.ExistsKeypoints(database.ReadImageWithName(name).ImageId())) {
      all_extracted = false;
    }
  }
  return all_extracted;
}

// COLMAP's SIFT extraction of the images not yet extracted (COLMAP skips the others).
void Extract(const std::vector<std::string>& names,
             const std::string& image_path,
             const DatasetImportSummary& summary,
             const DatasetImportOptions& options,
             const std::string& database_path) {
  colmap::ImageReaderOptions reader_options;
  reader_options.database_path = database_path;
  reader_options.image_path = image_path;
  reader_options.image_list = names;
  reader_options.existing_camera_id = static_cast<int>(summary.camera_id);
  std::cout << "COLMAP SIFT extraction (" << summary.num_new_images << " new images)" << std::endl;
  auto extractor =
      colmap::CreateFeatureExtractorController(reader_options, options.sift_extraction);
  extractor->Start();
  extractor->Wait();
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
                               names[i]);
    }
    const colmap::Image image = database.ReadImageWithName(names[i]);
    if (image.CameraId() != camera_id) {
      throw std::runtime_error("station " + dataset.stations[i] + ": image " + names[i] +
                               " already exists in the database with another camera (" +
                               std::to_string(image.CameraId()) + ")");
    }
    if (!database.ExistsKeypoints(image.ImageId())) {
      throw std::runtime_error("station " + dataset.stations[i] +
                               ": COLMAP extracted no features from " + names[i]);
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

// The image pairs of COLMAP's exhaustive, sequential or spatial pairing, each once, without those
// that have matches already (a user's database keeps its own).
std::vector<ImagePair> PairsToMatch(const DatasetImportOptions& options,
                                    const std::string& database_path) {
  const auto database = std::make_shared<colmap::Database>(database_path);
  std::unique_ptr<colmap::PairGenerator> generator;
  if (options.matcher == ImageMatcher::kSequential) {
    generator =
        std::make_unique<colmap::SequentialPairGenerator>(options.sequential_matching, database);
  } else if (options.matcher == ImageMatcher::kSpatial) {
    generator = std::make_unique<colmap::SpatialPairGenerator>(options.spatial_matching, database);
  } else {
    generator =
        std::make_unique<colmap::ExhaustivePairGenerator>(options.exhaustive_matching, database);
  }
  std::set<colmap::image_pair_t> seen;
  std::vector<ImagePair> pairs;
  for (const ImagePair& pair : generator->AllPairs()) {
    if (pair.first == pair.second) continue;
    if (!seen.insert(colmap::Database::ImagePairToPairId(pair.first, pair.second)).second) continue;
    if (!database->ExistsMatches(pair.first, pair.second)) pairs.push_back(pair);
  }
  return pairs;
}

// SIFT matching (sift_matching.h) of COLMAP's exhaustive, sequential or spatial pairs.
void MatchFeatures(const DatasetImportOptions& options, const std::string& database_path) {
  const std::vector<ImagePair> pairs = PairsToMatch(options, database_path);
  std::cout << "SIFT matching, COLMAP's " << ImageMatcherName(options.matcher)
            << " pairs: " << pairs.size() << " image pairs" << std::endl;
  MatchImagePairs(
      pairs, options.sift_matching, options.two_view_geometry.min_num_inliers, database_path);
}

// Spatial matching gives a station without a position (outside the LiDAR registration's largest
// component) no pair: such stations are matched with every other image, so that they can still
// join the model through their images: (stations without a position) x N pairs at most.
void MatchStationsWithoutPosition(const StationDataset& dataset,
                                  const std::vector<colmap::image_t>& image_ids,
                                  const DatasetImportOptions& options,
                                  const std::string& database_path) {
  std::vector<size_t> unplaced;
  for (size_t i = 0; i < image_ids.size(); ++i) {
    if (options.station_positions.count(dataset.stations[i]) == 0) unplaced.push_back(i);
  }
  if (unplaced.empty()) return;
  std::vector<ImagePair> pairs;
  {
    const colmap::Database database(database_path);
    for (size_t i : unplaced) {
      for (size_t j = 0; j < image_ids.size(); ++j) {
        const bool listed = options.station_positions.count(dataset.stations[j]) == 0 && j < i;
        if (j == i || listed || database.ExistsMatches(image_ids[i], image_ids[j])) continue;
        pairs.emplace_back(image_ids[i], image_ids[j]);
      }
    }
  }
  std::cout << "SIFT matching: " << unplaced.size()
            << " stations without a LiDAR position, each with every image (" << pairs.size()
            << " pairs)" << std::endl;
  MatchImagePairs(
      pairs, options.sift_matching, options.two_view_geometry.min_num_inliers, database_path);
}

// The pairs this import matched get their two-view geometries (pair_verification.h).
void VerifyNewPairs(const DatasetImportOptions& options,
                    const std::set<colmap::image_pair_t>& verified_before,
                    const std::string& database_path) {
  const size_t num_pairs = VerifyPairsDeterministically(
      options.two_view_geometry, verified_before, database_path, options.sift_matching.num_threads);
  std::cout << "Geometric verification (COLMAP's two-view geometry, RANSAC seeded per pair): "
            << num_pairs << " pairs" << std::endl;
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

// False for a database file without any table: what an import killed while copying into a new
// database leaves (SQLite rolls the copy back to the empty file). It holds nothing to keep, so the
// import treats it as new; any other file must be a COLMAP database.
bool HoldsTables(const std::string& path) {
  return SqliteConnection(path, SqliteConnection::Mode::kReadOnly, 1000).HasTables();
}

// " (... only N KiB free ...)" when the disk of `path` is (nearly) full, else "": COLMAP reports a
// full disk as "SQL logic error".
std::string DiskFullHint(const std::string& path) {
  std::error_code error;
  const fs::space_info space = fs::space(fs::absolute(path).parent_path(), error);
  if (error || space.available > (uint64_t(64) << 20)) return "";
  return " (writing " + path + ": only " + std::to_string(space.available / 1024) +
         " KiB free on its disk; is it full?)";
}

}  // namespace

std::string DatasetImportOptions::ImageName(const StationDataset& dataset, size_t station) const {
  if (image_name_format.empty()) return dataset.LeftImageName(station);
  std::string name = image_name_format;
  name.replace(name.find(kStationPlaceholder),
               std::string(kStationPlaceholder).size(),
               dataset.stations.at(station));
  return name;
}

const char* ImageMatcherName(ImageMatcher matcher) {
  return ChoiceName(kImageMatcherNames, matcher);
}

colmap::SpatialMatchingOptions LidarSpatialMatchingOptions() {
  colmap::SpatialMatchingOptions options;
  options.ignore_z = false;
  return options;
}

bool DatasetImportOptions::Check() const {
  CHECK_OPTION(image_name_format.empty() ||
               fs::path(image_name_format).stem().string() == kStationPlaceholder);
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

namespace {

// Every step of the import into the copy `partial`: camera, SIFT, images, matches, rig and LiDAR
// frames.
DatasetImportSummary ImportIntoPartial(const StationDataset& dataset,
                                       const DatasetImportOptions& options,
                                       const std::string& partial) {
  DatasetImportSummary summary;
  std::vector<std::string> names;
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    names.push_back(options.ImageName(dataset, i));
  }
  const std::string image_path = options.image_path.empty()
                                     ? (fs::path(dataset.root) / "images").string()
                                     : options.image_path;
  const bool all_extracted = PrepareCamera(dataset, names, image_path, options, partial, &summary);
  if (all_extracted) {
    std::cout << "COLMAP SIFT extraction: every station image has its features" << std::endl;
  } else {
    Extract(names, image_path, summary, options, partial);
  }
  const std::vector<colmap::image_t> image_ids =
      ImportedImageIds(dataset, names, summary.camera_id, partial);
  if (options.matcher == ImageMatcher::kSpatial)
    WritePosePriors(dataset, image_ids, options, partial);
  const std::set<colmap::image_pair_t> verified_before = VerifiedPairIds(partial);
  MatchFeatures(options, partial);
  if (options.matcher == ImageMatcher::kSpatial) {
    MatchStationsWithoutPosition(dataset, image_ids, options, partial);
  }
  VerifyNewPairs(options, verified_before, partial);
  WriteRigAndLidarFrames(dataset, summary.camera_id, image_ids, partial);
  const colmap::Database database(partial);
  summary.num_images = names.size();
  summary.num_verified_pairs = database.NumVerifiedImagePairs();
  return summary;
}

}  // namespace

DatasetImportSummary ImportDataset(const StationDataset& dataset,
                                   const std::string& database_path,
                                   const DatasetImportOptions& options) {
  THROW_CHECK(options.sift_extraction.Check());
  THROW_CHECK(options.sift_matching.Check());
  THROW_CHECK(!options.sift_matching.guided_matching)
      << "SiftMatching.guided_matching is not supported (sift_matching.h matches without it)";
  THROW_CHECK(options.two_view_geometry.Check());
  THROW_CHECK(options.Check());
  THROW_CHECK(options.matcher != ImageMatcher::kSpatial || !options.station_positions.empty())
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
  if (fs::exists(database_path) && HoldsTables(database_path)) {
    // Rejects a non-COLMAP file before anything is written; the copy is a consistent snapshot.
    { ExtensionDatabase check(database_path, ExtensionDatabase::Mode::kReadOnly); }
    CopySqliteDatabase(database_path, partial);
  }
  try {
    const DatasetImportSummary summary = ImportIntoPartial(dataset, options, partial);
    // Into the user's database in one transaction (SQLite's backup API: correct with COLMAP's WAL
    // journal, unlike a rename, and it waits for or reports other writers).
    CopySqliteDatabase(partial, database_path);
    remove_partial();
    return summary;
  } catch (const std::exception& error) {
    remove_partial();
    throw std::runtime_error(error.what() + DiskFullHint(database_path));
  }
}

}  // namespace colmap_lidar
