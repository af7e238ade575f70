#include "colmap_ext/colmap_tables.h"

#include "colmap_ext/sqlite_connection.h"

#include "colmap/scene/database.h"

#include <algorithm>

namespace colmap_lidar {
namespace {

constexpr int kBusyTimeoutMs = 5000;

}  // namespace

std::map<colmap::image_t, std::string> ReadImageNames(const std::string& database_path) {
  const SqliteConnection connection(
      database_path, SqliteConnection::Mode::kReadOnly, kBusyTimeoutMs);
  SqliteStatement select(connection, "SELECT image_id, name FROM images;");
  std::map<colmap::image_t, std::string> names;
  while (select.Step()) {
    names[static_cast<colmap::image_t>(select.ColumnInt64(0))] = select.ColumnText(1);
  }
  return names;
}

std::vector<VerifiedPairInliers> ReadVerifiedPairInliers(const std::string& database_path) {
  const SqliteConnection connection(
      database_path, SqliteConnection::Mode::kReadOnly, kBusyTimeoutMs);
  SqliteStatement select(
      connection, "SELECT pair_id, rows FROM two_view_geometries WHERE rows > 0 ORDER BY pair_id;");
  std::vector<VerifiedPairInliers> pairs;
  while (select.Step()) {
    const auto pair_id = static_cast<colmap::image_pair_t>(select.ColumnInt64(0));
    const auto [image_id1, image_id2] = colmap::Database::PairIdToImagePair(pair_id);
    pairs.push_back({std::min(image_id1, image_id2),
                     std::max(image_id1, image_id2),
                     static_cast<int>(select.ColumnInt64(1))});
  }
  return pairs;
}

}  // namespace colmap_lidar
