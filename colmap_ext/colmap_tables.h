// COLMAP's own tables (images, two_view_geometries) read through a read-only SQLite connection.
// colmap::Database opens read-write and runs its CREATE TABLE statements on open: that writes to a
// user's database a command only reads, and fails at once ("database is locked") while another
// process writes to it, such as a second joint_adjuster on the same database. These readers do
// neither; they wait up to the busy timeout for a writer's commit.
#pragma once

#include "colmap/util/types.h"

#include <map>
#include <string>
#include <vector>

namespace colmap_lidar {

// image_id -> name of every row of COLMAP's images table.
std::map<colmap::image_t, std::string> ReadImageNames(const std::string& database_path);

// A verified image pair (image_id1 < image_id2) with its number of inlier matches.
struct VerifiedPairInliers {
  colmap::image_t image_id1 = colmap::kInvalidImageId;
  colmap::image_t image_id2 = colmap::kInvalidImageId;
  int num_inliers = 0;
};

// The two-view geometries with at least one inlier, in pair id order (what
// colmap::Database::ReadTwoViewGeometryNumInliers reads).
std::vector<VerifiedPairInliers> ReadVerifiedPairInliers(const std::string& database_path);

}  // namespace colmap_lidar
