#include "colmap_ext/pair_verification.h"

#include "colmap_ext/sqlite_connection.h"
#include "lidar/util/parallel_for_each.h"

#include "colmap/math/random.h"
#include "colmap/scene/database.h"

#include <algorithm>
#include <map>
#include <utility>
#include <vector>

namespace colmap_lidar {
namespace {

// The keypoints' positions. Made here, not by COLMAP's FeatureKeypointsToPointsVector: COLMAP's
// library is built with Eigen's aligned allocator for std::vector<Eigen::Vector2d>
// (colmap/util/eigen_alignment.h before C++17), and a vector it allocates must not be freed by our
// C++17 code, which uses the standard allocator.
std::vector<Eigen::Vector2d> KeypointPositions(const colmap::FeatureKeypoints& keypoints) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(keypoints.size());
  for (const colmap::FeatureKeypoint& keypoint : keypoints) {
    points.emplace_back(keypoint.x, keypoint.y);
  }
  return points;
}

// The image points of every image that appears in `pairs`, read once.
std::map<colmap::image_t, std::vector<Eigen::Vector2d>> ReadPoints(
    const colmap::Database& database,
    const std::vector<std::pair<colmap::image_pair_t, colmap::FeatureMatches>>& pairs) {
  std::map<colmap::image_t, std::vector<Eigen::Vector2d>> points;
  for (const auto& [pair_id, matches] : pairs) {
    const auto [image_id1, image_id2] = colmap::Database::PairIdToImagePair(pair_id);
    for (const colmap::image_t image_id : {image_id1, image_id2}) {
      if (points.count(image_id) == 0) {
        points[image_id] = KeypointPositions(database.ReadKeypoints(image_id));
      }
    }
  }
  return points;
}

// A seed for the pair's RANSAC that is never COLMAP's "seed from the clock" value.
unsigned SeedOfPair(colmap::image_pair_t pair_id) {
  return static_cast<unsigned>(pair_id % 2147483647u);
}

}  // namespace

std::set<colmap::image_pair_t> VerifiedPairIds(const std::string& database_path) {
  // COLMAP's reader skips geometries without inliers; a failed verification is a verification too.
  const SqliteConnection connection(database_path, SqliteConnection::Mode::kReadOnly, 1000);
  SqliteStatement select(connection, "SELECT pair_id FROM two_view_geometries;");
  std::set<colmap::image_pair_t> pair_ids;
  while (select.Step()) pair_ids.insert(static_cast<colmap::image_pair_t>(select.ColumnInt64(0)));
  return pair_ids;
}

size_t VerifyPairsDeterministically(const colmap::TwoViewGeometryOptions& options,
                                    const std::set<colmap::image_pair_t>& keep,
                                    const std::string& database_path,
                                    int num_threads) {
  colmap::Database database(database_path);
  std::vector<std::pair<colmap::image_pair_t, colmap::FeatureMatches>> pairs;
  for (auto& pair : database.ReadAllMatches()) {
    if (keep.count(pair.first) == 0) pairs.push_back(std::move(pair));
  }
  std::sort(
      pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  const auto points = ReadPoints(database, pairs);
  std::map<colmap::image_t, colmap::Camera> cameras;
  for (const colmap::Image& image : database.ReadAllImages()) {
    cameras.emplace(image.ImageId(), database.ReadCamera(image.CameraId()));
  }
  std::vector<colmap::TwoViewGeometry> geometries(pairs.size());
  ParallelForEach(
      static_cast<int>(pairs.size()),
      [&](int i) {
        const colmap::FeatureMatches& matches = pairs[i].second;
        if (matches.size() < static_cast<size_t>(options.min_num_inliers)) return;
        const auto [id1, id2] = colmap::Database::PairIdToImagePair(pairs[i].first);
        colmap::SetPRNGSeed(SeedOfPair(pairs[i].first));
        colmap::TwoViewGeometry geometry = colmap::EstimateTwoViewGeometry(
            cameras.at(id1), points.at(id1), cameras.at(id2), points.at(id2), matches, options);
        if (geometry.inlier_matches.size() >= static_cast<size_t>(options.min_num_inliers)) {
          geometries[i] = std::move(geometry);
        }
      },
      num_threads);
  colmap::DatabaseTransaction transaction(&database);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const auto [id1, id2] = colmap::Database::PairIdToImagePair(pairs[i].first);
    database.DeleteInlierMatches(id1, id2);
    database.WriteTwoViewGeometry(id1, id2, geometries[i]);
  }
  return pairs.size();
}

}  // namespace colmap_lidar
