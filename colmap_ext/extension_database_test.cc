#include "colmap_ext/extension_database.h"

#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/database.h"
#include "colmap/sensor/models.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// A COLMAP database in a fresh temporary directory with one camera and `num_images` images.
class ExtensionDatabaseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = dir_.File("database.db");
    colmap::Database database(path_);
    const colmap::Camera camera =
        colmap::Camera::CreateFromModelName(colmap::kInvalidCameraId, "PINHOLE", 800, 1028, 752);
    camera_id_ = database.WriteCamera(camera);
    for (int i = 0; i < 3; ++i) {
      colmap::Image image;
      image.SetName("left/00" + std::to_string(i) + ".png");
      image.SetCameraId(camera_id_);
      image_ids_.push_back(database.WriteImage(image));
    }
  }

  static std::vector<DepthPrior> MakePriors(int n, double depth0) {
    std::vector<DepthPrior> priors;
    for (int i = 0; i < n; ++i) {
      priors.push_back({static_cast<colmap::point2D_t>(2 * i), depth0 + 0.01 * i, 0.001 * (i + 1)});
    }
    return priors;
  }

  testing::ScopedTempDir dir_;
  std::string path_;
  colmap::camera_t camera_id_ = 0;
  std::vector<colmap::image_t> image_ids_;
};

TEST_F(ExtensionDatabaseTest, RoundTripsAllTables) {
  {
    ExtensionDatabase db(path_);
    db.WriteDepthPriors(image_ids_[0], MakePriors(50, 2.0));
    db.WriteDepthPriors(image_ids_[1], MakePriors(7, 3.0));

    LidarFrame frame;
    frame.image_id = image_ids_[0];
    frame.path = "lidar/000.pcd";
    frame.cam_from_lidar_guess = colmap::Rigid3d(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
        Eigen::Vector3d(0.1, -0.2, 0.05));
    EXPECT_GT(db.WriteLidarFrame(frame), 0);
    LidarFrame frame_without_guess;
    frame_without_guess.image_id = image_ids_[1];
    frame_without_guess.path = "lidar/001.pcd";
    db.WriteLidarFrame(frame_without_guess);

    StereoRig rig;
    rig.left_camera_id = camera_id_;
    rig.right_camera =
        colmap::Camera::CreateFromModelName(colmap::kInvalidCameraId, "OPENCV", 805, 1028, 752);
    rig.right_camera.params[4] = -0.05;
    rig.right_from_left.translation = Eigen::Vector3d(-0.38, 0.001, 0.002);
    db.WriteRig(rig);
  }
  // A fresh connection sees exactly what was written.
  ExtensionDatabase db(path_, ExtensionDatabase::Mode::kReadOnly);
  EXPECT_EQ(db.NumDepthPriors(), 57u);
  const std::vector<DepthPrior> priors = db.ReadDepthPriors(image_ids_[0]);
  ASSERT_EQ(priors.size(), 50u);
  EXPECT_EQ(priors[10].point2D_idx, 20u);
  EXPECT_DOUBLE_EQ(priors[10].depth, 2.1);
  EXPECT_DOUBLE_EQ(priors[10].sigma, 0.011);
  EXPECT_TRUE(db.ReadDepthPriors(image_ids_[2]).empty());

  const std::vector<LidarFrame> frames = db.ReadLidarFrames();
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].path, "lidar/000.pcd");
  ASSERT_TRUE(frames[0].cam_from_lidar_guess.has_value());
  EXPECT_NEAR(frames[0].cam_from_lidar_guess->rotation.angularDistance(Eigen::Quaterniond(
                  Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()))),
              0,
              1e-12);
  EXPECT_NEAR(frames[0].cam_from_lidar_guess->translation.y(), -0.2, 1e-15);
  EXPECT_FALSE(frames[1].cam_from_lidar_guess.has_value());

  const std::optional<StereoRig> rig = db.ReadRig();
  ASSERT_TRUE(rig.has_value());
  EXPECT_EQ(rig->left_camera_id, camera_id_);
  EXPECT_EQ(rig->right_camera.ModelName(), "OPENCV");
  EXPECT_EQ(rig->right_camera.width, 1028u);
  ASSERT_EQ(rig->right_camera.params.size(), 8u);
  EXPECT_DOUBLE_EQ(rig->right_camera.params[4], -0.05);
  EXPECT_NEAR(rig->BaselineMeters(), std::sqrt(0.38 * 0.38 + 0.000005), 1e-12);
}

TEST_F(ExtensionDatabaseTest, RewritingDoesNotDuplicate) {
  ExtensionDatabase db(path_);
  db.WriteDepthPriors(image_ids_[0], MakePriors(20, 2.0));
  db.WriteDepthPriors(image_ids_[0], MakePriors(5, 2.5));
  EXPECT_EQ(db.NumDepthPriors(), 5u);
  LidarFrame frame;
  frame.image_id = image_ids_[2];
  frame.path = "lidar/a.pcd";
  const int64_t id = db.WriteLidarFrame(frame);
  frame.path = "lidar/b.pcd";
  EXPECT_EQ(db.WriteLidarFrame(frame), id);
  ASSERT_EQ(db.ReadLidarFrames().size(), 1u);
  EXPECT_EQ(db.ReadLidarFrames()[0].path, "lidar/b.pcd");
}

TEST_F(ExtensionDatabaseTest, FailedWriteRollsBackWholeTransaction) {
  ExtensionDatabase db(path_);
  db.WriteDepthPriors(image_ids_[0], MakePriors(10, 2.0));
  // The last row violates CHECK(depth > 0): the delete of the old rows and the first inserts roll back.
  std::vector<DepthPrior> bad = MakePriors(30, 4.0);
  bad.back().depth = -1;
  EXPECT_THROW(db.WriteDepthPriors(image_ids_[0], bad), std::runtime_error);
  const std::vector<DepthPrior> after = db.ReadDepthPriors(image_ids_[0]);
  ASSERT_EQ(after.size(), 10u);
  EXPECT_DOUBLE_EQ(after[0].depth, 2.0);
}

TEST_F(ExtensionDatabaseTest, ForeignKeysRejectUnknownImagesAndCameras) {
  ExtensionDatabase db(path_);
  EXPECT_THROW(db.WriteDepthPriors(9999, MakePriors(3, 1.0)), std::runtime_error);
  LidarFrame frame;
  frame.image_id = 9999;
  frame.path = "lidar/x.pcd";
  EXPECT_THROW(db.WriteLidarFrame(frame), std::runtime_error);
  StereoRig rig;
  rig.left_camera_id = 4242;
  rig.right_camera =
      colmap::Camera::CreateFromModelName(colmap::kInvalidCameraId, "PINHOLE", 800, 10, 10);
  rig.right_from_left.translation.x() = -0.38;
  EXPECT_THROW(db.WriteRig(rig), std::runtime_error);
  EXPECT_EQ(db.NumDepthPriors(), 0u);
  EXPECT_TRUE(db.ReadLidarFrames().empty());
  EXPECT_FALSE(db.ReadRig().has_value());
}

TEST_F(ExtensionDatabaseTest, DeletingAnImageInColmapCascadesToOurRows) {
  {
    ExtensionDatabase db(path_);
    db.WriteDepthPriors(image_ids_[0], MakePriors(10, 2.0));
    db.WriteDepthPriors(image_ids_[1], MakePriors(4, 2.0));
  }
  {
    colmap::Database database(path_);
    database.ClearImages();  // COLMAP's own connection, foreign keys on.
  }
  ExtensionDatabase db(path_);
  EXPECT_EQ(db.NumDepthPriors(), 0u);
}

TEST_F(ExtensionDatabaseTest, LockedDatabaseGivesClearErrorAndNoChange) {
  ExtensionDatabase db(path_,
                       ExtensionDatabase::Mode::kReadWrite,
                       /*busy_timeout_ms=*/100);
  db.WriteDepthPriors(image_ids_[0], MakePriors(3, 2.0));
  sqlite3* other = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &other), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(other, "BEGIN EXCLUSIVE", nullptr, nullptr, nullptr), SQLITE_OK);
  try {
    db.WriteDepthPriors(image_ids_[0], MakePriors(8, 5.0));
    ADD_FAILURE() << "write to a locked database succeeded";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("lock"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find(path_), std::string::npos);
  }
  sqlite3_exec(other, "ROLLBACK", nullptr, nullptr, nullptr);
  sqlite3_close(other);
  EXPECT_EQ(db.ReadDepthPriors(image_ids_[0]).size(), 3u);
}

TEST_F(ExtensionDatabaseTest, ReadOnlyDatabaseRefusesWrites) {
  { ExtensionDatabase db(path_); }
  ExtensionDatabase db(path_, ExtensionDatabase::Mode::kReadOnly);
  try {
    db.WriteDepthPriors(image_ids_[0], MakePriors(3, 2.0));
    ADD_FAILURE() << "write to a read-only database succeeded";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("read-only"), std::string::npos) << error.what();
  }
  EXPECT_EQ(db.NumDepthPriors(), 0u);
}

TEST_F(ExtensionDatabaseTest, RejectsMissingAndNonColmapFiles) {
  const std::string missing = dir_.File("missing.db");
  try {
    ExtensionDatabase db(missing);
    ADD_FAILURE();
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(missing), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(missing)) << "opening must never create a file";

  const std::string text = dir_.File("notes.db");
  std::ofstream(text) << "this is not an sqlite database, just some text....";
  EXPECT_THROW(ExtensionDatabase db(text), std::runtime_error);

  const std::string empty_sqlite = dir_.File("empty.db");
  sqlite3* handle = nullptr;
  sqlite3_open(empty_sqlite.c_str(), &handle);
  sqlite3_exec(handle, "CREATE TABLE other(x)", nullptr, nullptr, nullptr);
  sqlite3_close(handle);
  try {
    ExtensionDatabase db(empty_sqlite);
    ADD_FAILURE();
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("Not a COLMAP database"), std::string::npos);
  }
}

}  // namespace
}  // namespace colmap_lidar
