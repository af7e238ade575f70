#include "bridge/initialization/track_triangulation.h"

#include "colmap_ext/sqlite_connection.h"

#include "colmap/controllers/incremental_mapper.h"
#include "colmap/scene/database.h"
#include "colmap/scene/reconstruction_manager.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <set>
#include <utility>
#include <vector>

namespace colmap_lidar {
namespace {

using Observation = std::pair<colmap::image_t, colmap::point2D_t>;

// A private snapshot of the database, removed with this object. COLMAP's Database opens its file for
// writing (it creates missing tables) and fails at once while another process holds a lock; the
// snapshot (CopySqliteDatabase waits for writers) keeps both the input database untouched and the
// triangulation free of other programs' locks.
class DatabaseSnapshot {
 public:
  explicit DatabaseSnapshot(const std::string& database_path) {
    static std::atomic<int> counter{0};
    path_ = (std::filesystem::temp_directory_path() /
             ("colmap_lidar_tracks_" + std::to_string(::getpid()) + "_" +
              std::to_string(counter++) + ".db"))
                .string();
    CopySqliteDatabase(database_path, path_);
  }
  ~DatabaseSnapshot() {
    std::error_code ignored;
    for (const char* suffix : {"", "-wal", "-shm"})
      std::filesystem::remove(path_ + suffix, ignored);
  }
  DatabaseSnapshot(const DatabaseSnapshot&) = delete;
  DatabaseSnapshot& operator=(const DatabaseSnapshot&) = delete;

  const std::string& Path() const { return path_; }

 private:
  std::string path_;
};

// The images with at least one verified match in the database.
std::set<colmap::image_t> MatchedImages(const colmap::Database& database) {
  std::set<colmap::image_t> matched;
  std::vector<std::pair<colmap::image_t, colmap::image_t>> pairs;
  std::vector<int> num_inliers;
  database.ReadTwoViewGeometryNumInliers(&pairs, &num_inliers);
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (num_inliers[k] > 0) {
      matched.insert(pairs[k].first);
      matched.insert(pairs[k].second);
    }
  }
  return matched;
}

// The database's image at `cam_from_world` with its keypoints as points2D.
colmap::Image ImageAtPose(const colmap::Database& database,
                          colmap::image_t image_id,
                          const colmap::Rigid3d& cam_from_world) {
  colmap::Image image = database.ReadImage(image_id);
  image.CamFromWorld() = cam_from_world;
  // Built here, not by COLMAP's FeatureKeypointsToPointsVector: a vector of Eigen types allocated
  // inside COLMAP's library and freed here may pair different allocators (ASan reports it).
  std::vector<Eigen::Vector2d> points2D;
  for (const colmap::FeatureKeypoint& keypoint : database.ReadKeypoints(image_id)) {
    points2D.emplace_back(keypoint.x, keypoint.y);
  }
  image.SetPoints2D(points2D);
  return image;
}

// COLMAP's triangulator with the registered images' poses and the cameras held fixed.
void TriangulateRegistered(const std::string& database_path,
                           const std::shared_ptr<colmap::Reconstruction>& reconstruction) {
  if (reconstruction->NumRegImages() < 2) return;
  auto options = std::make_shared<colmap::IncrementalMapperOptions>();
  options->fix_existing_images = true;
  options->ba_refine_focal_length = false;
  options->ba_refine_principal_point = false;
  options->ba_refine_extra_params = false;
  // One thread: with more, Ceres sums the landmark-only adjustment's partial results in the order
  // its threads finish, which makes the landmarks (and the joint adjustment on them) depend on the
  // machine's core count in their last digits.
  options->num_threads = 1;
  colmap::IncrementalMapperController mapper(
      options, "", database_path, std::make_shared<colmap::ReconstructionManager>());
  mapper.TriangulateReconstruction(reconstruction);
}

// The landmark of each observation.
std::map<Observation, colmap::point3D_t> LandmarkOfObservation(
    const colmap::Reconstruction& model) {
  std::map<Observation, colmap::point3D_t> landmark_of;
  for (const auto& [point3D_id, point3D] : model.Points3D()) {
    for (const colmap::TrackElement& element : point3D.track.Elements()) {
      landmark_of[{element.image_id, element.point2D_idx}] = point3D_id;
    }
  }
  return landmark_of;
}

// Whether `after` holds a landmark observed by exactly the observations of `track`.
bool TrackKept(const colmap::Track& track,
               const std::map<Observation, colmap::point3D_t>& landmark_of,
               const colmap::Reconstruction& after) {
  std::set<colmap::point3D_t> landmarks;
  for (const colmap::TrackElement& element : track.Elements()) {
    const auto found = landmark_of.find({element.image_id, element.point2D_idx});
    if (found == landmark_of.end()) return false;
    landmarks.insert(found->second);
  }
  return landmarks.size() == 1 &&
         after.Point3D(*landmarks.begin()).track.Length() == track.Length();
}

}  // namespace

std::shared_ptr<colmap::Reconstruction> TriangulateAtPoses(
    const std::string& database_path,
    const std::map<colmap::camera_t, colmap::Camera>& cameras,
    const std::map<colmap::image_t, colmap::Rigid3d>& cam_from_world) {
  const DatabaseSnapshot snapshot(database_path);
  auto reconstruction = std::make_shared<colmap::Reconstruction>();
  // Images without any match would break COLMAP's observation manager: they join afterwards.
  std::vector<colmap::Image> without_correspondences;
  {
    const colmap::Database database(snapshot.Path());
    for (const auto& [camera_id, camera] : cameras) reconstruction->AddCamera(camera);
    const std::set<colmap::image_t> matched = MatchedImages(database);
    for (const auto& [image_id, pose] : cam_from_world) {
      colmap::Image image = ImageAtPose(database, image_id, pose);
      if (matched.count(image_id)) {
        reconstruction->AddImage(image);
        reconstruction->RegisterImage(image_id);
      } else {
        without_correspondences.push_back(image);
      }
    }
  }
  TriangulateRegistered(snapshot.Path(), reconstruction);
  for (const colmap::Image& image : without_correspondences) {
    reconstruction->AddImage(image);
    reconstruction->RegisterImage(image.ImageId());
  }
  return reconstruction;
}

void RetriangulateTracks(const std::string& database_path, colmap::Reconstruction* reconstruction) {
  std::map<colmap::image_t, colmap::Rigid3d> cam_from_world;
  for (const colmap::image_t image_id : reconstruction->RegImageIds()) {
    cam_from_world[image_id] = reconstruction->Image(image_id).CamFromWorld();
  }
  const std::map<colmap::camera_t, colmap::Camera> cameras(reconstruction->Cameras().begin(),
                                                           reconstruction->Cameras().end());
  *reconstruction = *TriangulateAtPoses(database_path, cameras, cam_from_world);
}

double FractionOfObservationsRetracked(const colmap::Reconstruction& before,
                                       const colmap::Reconstruction& after) {
  const std::map<Observation, colmap::point3D_t> landmark_of = LandmarkOfObservation(after);
  size_t observations = 0;
  size_t retracked = 0;
  for (const auto& [point3D_id, point3D] : before.Points3D()) {
    observations += point3D.track.Length();
    if (!TrackKept(point3D.track, landmark_of, after)) retracked += point3D.track.Length();
  }
  return observations == 0 ? 0 : static_cast<double>(retracked) / observations;
}

}  // namespace colmap_lidar
