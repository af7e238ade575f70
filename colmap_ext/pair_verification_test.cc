#include "colmap_ext/pair_verification.h"

#include "tests/testing/feature_matches.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/database.h"
#include "colmap/sensor/models.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// Four images of one random scene from cameras 0.3 m apart, keypoints with 2 px noise (half the
// verification's 4 px threshold); each pair's matches are the true correspondences plus 40 % random
// outliers, so RANSAC's draws decide which borderline matches count as inliers.
class PairVerificationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = dir_.File("database.db");
    colmap::Database database(path_);
    const colmap::Camera camera =
        colmap::Camera::CreateFromModelName(colmap::kInvalidCameraId, "PINHOLE", 500, 640, 480);
    const colmap::camera_t camera_id = database.WriteCamera(camera);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> lateral(-4, 4), depth(6, 14), pixel(0, 640);
    std::vector<Eigen::Vector3d> scene(300);
    for (Eigen::Vector3d& point : scene) point = {lateral(random), lateral(random), depth(random)};
    for (int i = 0; i < kNumImages; ++i) {
      colmap::Image image;
      image.SetName(std::to_string(i) + ".png");
      image.SetCameraId(camera_id);
      ids_.push_back(database.WriteImage(image));
      colmap::FeatureKeypoints keypoints;
      for (const Eigen::Vector3d& point : scene) {
        const Eigen::Vector3d in_camera = point - Eigen::Vector3d(0.3 * i, 0.1 * i, 0);
        const Eigen::Vector2d uv = camera.ImgFromCam(in_camera.hnormalized());
        keypoints.emplace_back(uv.x() + 2 * std::normal_distribution<>()(random),
                               uv.y() + 2 * std::normal_distribution<>()(random));
      }
      database.WriteKeypoints(ids_.back(), keypoints);
    }
    std::uniform_int_distribution<int> any(0, static_cast<int>(scene.size()) - 1);
    std::bernoulli_distribution outlier(0.4);
    for (int a = 0; a < kNumImages; ++a) {
      for (int b = a + 1; b < kNumImages; ++b) {
        colmap::FeatureMatches matches;
        for (int k = 0; k < static_cast<int>(scene.size()); ++k) {
          matches.emplace_back(k, outlier(random) ? any(random) : k);
        }
        database.WriteMatches(ids_[a], ids_[b], matches);
        database.WriteTwoViewGeometry(ids_[a], ids_[b], colmap::TwoViewGeometry());
      }
    }
  }

  // Every pair's configuration and inlier matches, in pair order.
  static std::vector<std::pair<int, colmap::FeatureMatches>> Geometries(const std::string& path) {
    const colmap::Database database(path);
    std::vector<colmap::image_pair_t> ids;
    std::vector<colmap::TwoViewGeometry> geometries;
    database.ReadTwoViewGeometries(&ids, &geometries);
    std::map<colmap::image_pair_t, std::pair<int, colmap::FeatureMatches>> by_id;
    for (size_t i = 0; i < ids.size(); ++i) {
      by_id[ids[i]] = {geometries[i].config, geometries[i].inlier_matches};
    }
    std::vector<std::pair<int, colmap::FeatureMatches>> ordered;
    for (const auto& [id, geometry] : by_id) ordered.push_back(geometry);
    return ordered;
  }

  std::string Copy(const std::string& name) {
    const std::string copy = dir_.File(name);
    fs::copy_file(path_, copy);
    return copy;
  }

  static constexpr int kNumImages = 4;
  testing::ScopedTempDir dir_;
  std::string path_;
  std::vector<colmap::image_t> ids_;
};

TEST_F(PairVerificationTest, SameGeometriesForOneAndTwoThreads) {
  const std::string one = Copy("one.db"), two = Copy("two.db");
  colmap::TwoViewGeometryOptions options;
  EXPECT_EQ(VerifyPairsDeterministically(options, {}, one, 1), 6u);
  EXPECT_EQ(VerifyPairsDeterministically(options, {}, two, 2), 6u);
  const auto geometries_one = Geometries(one), geometries_two = Geometries(two);
  ASSERT_EQ(geometries_one.size(), 6u);
  ASSERT_EQ(geometries_two.size(), 6u);
  for (size_t i = 0; i < geometries_one.size(); ++i) {
    EXPECT_EQ(geometries_one[i].first, geometries_two[i].first) << "pair " << i;
    EXPECT_TRUE(testing::SameMatches(geometries_one[i].second, geometries_two[i].second))
        << "pair " << i;
    // About 60 % of the 300 matches are true; the outliers that happen to fit stay few (measured
    // 160-191 inliers per pair).
    EXPECT_GT(geometries_one[i].second.size(), 150u);
    EXPECT_LT(geometries_one[i].second.size(), 200u);
  }
}

TEST_F(PairVerificationTest, KeepsThePairsVerifiedBefore) {
  const std::set<colmap::image_pair_t> keep = {
      colmap::Database::ImagePairToPairId(ids_[0], ids_[1])};
  ASSERT_EQ(VerifiedPairIds(path_).size(), 6u);
  EXPECT_EQ(VerifyPairsDeterministically(colmap::TwoViewGeometryOptions(), keep, path_, 0), 5u);
  const colmap::Database database(path_);
  EXPECT_TRUE(database.ReadTwoViewGeometry(ids_[0], ids_[1]).inlier_matches.empty());
  EXPECT_GT(database.ReadTwoViewGeometry(ids_[0], ids_[2]).inlier_matches.size(), 150u);
}

TEST_F(PairVerificationTest, TooFewInliersGiveAnEmptyGeometry) {
  colmap::TwoViewGeometryOptions options;
  options.min_num_inliers = 250;
  EXPECT_EQ(VerifyPairsDeterministically(options, {}, path_, 2), 6u);
  for (const auto& [config, inliers] : Geometries(path_)) {
    EXPECT_EQ(config, colmap::TwoViewGeometry::UNDEFINED);
    EXPECT_TRUE(inliers.empty());
  }
}

}  // namespace
}  // namespace colmap_lidar
