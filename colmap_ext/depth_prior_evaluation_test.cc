#include "colmap_ext/depth_prior_evaluation.h"

#include "colmap_ext/extension_database.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/mvs/depth_map.h"
#include "colmap/scene/database.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 64, kHeight = 48;

// A wall at 4 m with a post at 2 m in columns [30, 34).
double TrueDepth(int col) { return col >= 30 && col < 34 ? 2.0 : 4.0; }

// One image "left/000.png" whose keypoints sit at every pixel centre of rows 10..29; its priors are
// the true depth plus Gaussian noise of sigma (seeded), and the true depth map in DIR/truth/000.bin.
class DepthPriorEvaluationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    database_path_ = dir_.File("database.db");
    colmap::Database database(database_path_);
    const colmap::camera_t camera_id = database.WriteCamera(colmap::Camera::CreateFromModelName(
        colmap::kInvalidCameraId, "PINHOLE", 50, kWidth, kHeight));
    colmap::Image image;
    image.SetName("left/000.png");
    image.SetCameraId(camera_id);
    image_id_ = database.WriteImage(image);
    colmap::FeatureKeypoints keypoints;
    for (int row = 10; row < 30; ++row) {
      for (int col = 0; col < kWidth; ++col) keypoints.emplace_back(col + 0.5f, row + 0.5f);
    }
    database.WriteKeypoints(image_id_, keypoints);
    colmap::mvs::DepthMap truth(kWidth, kHeight, 0.f, 5.f);
    for (int row = 0; row < kHeight; ++row) {
      for (int col = 0; col < kWidth; ++col) truth.Set(row, col, TrueDepth(col));
    }
    fs::create_directories(dir_.File("truth"));
    truth.Write(dir_.File("truth/000.bin"));
  }

  // Priors with errors of `noise_in_sigmas` sigma (Gaussian); the columns in `shifted` get the
  // other side's depth (a fattened edge).
  void WritePriors(double noise_in_sigmas, const std::vector<int>& shifted) {
    std::mt19937 random(7);
    std::normal_distribution<double> noise(0, noise_in_sigmas);
    std::vector<DepthPrior> priors;
    for (int row = 10; row < 30; ++row) {
      for (int col = 0; col < kWidth; ++col) {
        DepthPrior prior;
        prior.point2D_idx = (row - 10) * kWidth + col;
        prior.sigma = 0.01 * TrueDepth(col);
        const bool fattened = std::count(shifted.begin(), shifted.end(), col) > 0;
        prior.depth =
            (fattened ? 6.0 - TrueDepth(col) : TrueDepth(col)) + prior.sigma * noise(random);
        priors.push_back(prior);
      }
    }
    ExtensionDatabase(database_path_).WriteDepthPriors(image_id_, priors);
  }

  testing::ScopedTempDir dir_;
  std::string database_path_;
  colmap::image_t image_id_ = 0;
};

TEST_F(DepthPriorEvaluationTest, GaussianPriorsCoverLikeAGaussian) {
  WritePriors(1.0, {});
  const DepthPriorEvaluation evaluation =
      EvaluateDepthPriors(database_path_, dir_.File("truth"), DepthPriorEvaluationOptions());
  ASSERT_EQ(evaluation.all.num_priors, 20u * kWidth);
  // 1280 draws: the binomial standard deviation of the 1-sigma fraction is 1.3 %.
  EXPECT_NEAR(evaluation.all.within_1_sigma, 0.683, 0.04);
  EXPECT_NEAR(evaluation.all.within_2_sigma, 0.954, 0.02);
  EXPECT_NEAR(evaluation.all.mean_normalized_error, 0, 0.1);
  EXPECT_EQ(evaluation.all.beyond_10_sigma, 0);
  // The post's two edges: columns 28..35 lie within 2 px of a depth jump (8 of 64 columns).
  EXPECT_EQ(evaluation.at_edges.num_priors, 20u * 8);
}

TEST_F(DepthPriorEvaluationTest, AFattenedEdgeShowsAsGrossErrorsAtTheEdge) {
  // Block matching's foreground fattening: the wall's columns 28, 29 take the post's depth.
  WritePriors(0.1, {28, 29});
  const DepthPriorEvaluation evaluation =
      EvaluateDepthPriors(database_path_, dir_.File("truth"), DepthPriorEvaluationOptions());
  EXPECT_NEAR(evaluation.at_edges.beyond_10_sigma, 2.0 / 8, 1e-12);
  EXPECT_EQ(evaluation.away_from_edges.beyond_10_sigma, 0);
  // The wall's priors come out 2 m near: a negative mean error.
  EXPECT_LT(evaluation.at_edges.mean_normalized_error, -10);
  // The gate keeps the rest: no bias reaches the solution.
  EXPECT_EQ(evaluation.inliers.num_priors, 20u * (kWidth - 2));
  EXPECT_NEAR(evaluation.inliers.mean_normalized_error, 0, 0.02);
}

TEST_F(DepthPriorEvaluationTest, RefusesTrueDepthOfAnotherSizeATruncatedOneAndAFolderWithout) {
  WritePriors(1.0, {});
  colmap::mvs::DepthMap other(kWidth / 2, kHeight, 0.f, 5.f);
  other.Write(dir_.File("truth/000.bin"));
  try {
    EvaluateDepthPriors(database_path_, dir_.File("truth"), DepthPriorEvaluationOptions());
    FAIL() << "a true depth map of another size was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("000.bin"), std::string::npos) << error.what();
  }
  // A truncated file: one error naming it, not a crash.
  {
    std::ofstream truncated(dir_.File("truth/000.bin"), std::ios::binary);
    truncated << kWidth << "&" << kHeight << "&1&" << std::string(100, '\0');
  }
  try {
    EvaluateDepthPriors(database_path_, dir_.File("truth"), DepthPriorEvaluationOptions());
    FAIL() << "a truncated true depth map was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("000.bin"), std::string::npos) << error.what();
  }
  fs::create_directories(dir_.File("empty"));
  try {
    EvaluateDepthPriors(database_path_, dir_.File("empty"), DepthPriorEvaluationOptions());
    FAIL() << "a folder without true depth was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("no image"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace colmap_lidar
