#include "colmap_ext/colmap_tables.h"

#include "colmap_ext/sqlite_connection.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/database.h"
#include "colmap/sensor/models.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace colmap_lidar {
namespace {

colmap::TwoViewGeometry GeometryWithInliers(int num_inliers) {
  colmap::TwoViewGeometry geometry;
  geometry.config = colmap::TwoViewGeometry::CALIBRATED;
  for (int k = 0; k < num_inliers; ++k) geometry.inlier_matches.emplace_back(k, k);
  return geometry;
}

// Three images; pairs (1, 2) with 30 inliers, (1, 3) verified without inliers, (3, 2) with 12.
class ColmapTablesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = dir_.File("database.db");
    colmap::Database database(path_);
    const colmap::camera_t camera_id = database.WriteCamera(
        colmap::Camera::CreateFromModelName(colmap::kInvalidCameraId, "PINHOLE", 500, 640, 480));
    for (const char* name : {"left/a.png", "left/b.png", "left/c.png"}) {
      colmap::Image image;
      image.SetName(name);
      image.SetCameraId(camera_id);
      ids_.push_back(database.WriteImage(image));
    }
    database.WriteTwoViewGeometry(ids_[0], ids_[1], GeometryWithInliers(30));
    database.WriteTwoViewGeometry(ids_[0], ids_[2], GeometryWithInliers(0));
    database.WriteTwoViewGeometry(ids_[2], ids_[1], GeometryWithInliers(12));
  }

  testing::ScopedTempDir dir_;
  std::string path_;
  std::vector<colmap::image_t> ids_;
};

TEST_F(ColmapTablesTest, ReadsWhatColmapsDatabaseReads) {
  const std::map<colmap::image_t, std::string> names = ReadImageNames(path_);
  ASSERT_EQ(names.size(), 3u);
  EXPECT_EQ(names.at(ids_[1]), "left/b.png");
  const std::vector<VerifiedPairInliers> pairs = ReadVerifiedPairInliers(path_);
  std::vector<std::pair<colmap::image_t, colmap::image_t>> colmap_pairs;
  std::vector<int> colmap_inliers;
  colmap::Database(path_).ReadTwoViewGeometryNumInliers(&colmap_pairs, &colmap_inliers);
  ASSERT_EQ(pairs.size(), 2u);
  ASSERT_EQ(colmap_pairs.size(), pairs.size());
  for (const VerifiedPairInliers& pair : pairs) {
    EXPECT_LT(pair.image_id1, pair.image_id2);
    const auto it = std::find_if(colmap_pairs.begin(), colmap_pairs.end(), [&](const auto& p) {
      return std::minmax(p.first, p.second) == std::minmax(pair.image_id1, pair.image_id2);
    });
    ASSERT_NE(it, colmap_pairs.end());
    EXPECT_EQ(colmap_inliers[it - colmap_pairs.begin()], pair.num_inliers);
  }
  EXPECT_EQ(pairs[0].num_inliers, 30);
  EXPECT_EQ(pairs[1].image_id1, ids_[1]);
  EXPECT_EQ(pairs[1].image_id2, ids_[2]);
  EXPECT_EQ(pairs[1].num_inliers, 12);
}

TEST_F(ColmapTablesTest, ReadsTheCommittedStateWhileAnotherConnectionWrites) {
  const SqliteConnection writer(path_, SqliteConnection::Mode::kReadWrite, 0);
  SqliteTransaction transaction(writer);
  writer.Execute("UPDATE images SET name = 'renamed_' || name;");
  writer.Execute("DELETE FROM two_view_geometries;");
  EXPECT_EQ(ReadImageNames(path_).at(ids_[0]), "left/a.png");
  EXPECT_EQ(ReadVerifiedPairInliers(path_).size(), 2u);
}

TEST_F(ColmapTablesTest, AFileWithoutColmapsTablesIsAnErrorNamingIt) {
  const std::string other = dir_.File("other.db");
  CopySqliteDatabase(path_, other);
  SqliteConnection(other, SqliteConnection::Mode::kReadWrite, 0).Execute("DROP TABLE images;");
  try {
    ReadImageNames(other);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(other), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace colmap_lidar
