#include "colmap_ext/dense_depth_evaluation.h"

#include "colmap_ext/dense_workspace.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/mvs/depth_map.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <random>

namespace colmap_lidar {
namespace {

constexpr int kWidth = 80, kHeight = 60;

// Truth: a plane at 4 m with a sky strip (depth 0) in the top 10 rows. Dense: the left half with the
// truth plus Gaussian noise of `sigma_m` and 2 % of its pixels 0.5 m off (edge fattening); the right
// half without depth but for an infinite and a NaN pixel.
class DenseDepthEvaluationTest : public ::testing::Test {
 protected:
  void Write(double sigma_m) {
    std::mt19937 rng(4);
    std::normal_distribution<double> noise(0, sigma_m);
    std::uniform_real_distribution<double> unit(0, 1);
    colmap::mvs::DepthMap truth(kWidth, kHeight, 0.f, 10.f);
    cv::Mat dense(kHeight, kWidth, CV_32F, cv::Scalar(0));
    for (int row = 0; row < kHeight; ++row) {
      for (int col = 0; col < kWidth; ++col) {
        truth.Set(row, col, row < 10 ? 0.f : 4.f);
        if (col < kWidth / 2) {
          dense.at<float>(row, col) = float(4 + noise(rng) + (unit(rng) < 0.02 ? 0.5 : 0.0));
        }
      }
    }
    // Not finite: no depth (counted nowhere).
    dense.at<float>(0, kWidth - 1) = std::numeric_limits<float>::infinity();
    dense.at<float>(1, kWidth - 1) = std::numeric_limits<float>::quiet_NaN();
    std::filesystem::create_directories(dir_.File("truth"));
    truth.Write(dir_.File("truth/000.bin"));
    const DenseWorkspace workspace(dir_.File("dense"));
    workspace.WriteConfigs({"left/000.png", "left/001.png"});
    workspace.WriteDepthMap("left/000.png", dense);
    workspace.WriteDepthMap("left/001.png", dense);  // no true depth map for 001
  }

  testing::ScopedTempDir dir_;
};

TEST_F(DenseDepthEvaluationTest, MeasuresCoverageErrorQuantilesAndBias) {
  Write(0.005);
  const DenseDepthEvaluation evaluation =
      EvaluateDenseDepth(dir_.File("dense"), dir_.File("truth"));
  ASSERT_EQ(evaluation.image_names.size(), 1u);
  ASSERT_EQ(evaluation.images_without_truth.size(), 1u);
  const DenseDepthStatistics& all = evaluation.all;
  EXPECT_EQ(all.num_pixels, size_t(kWidth * kHeight));
  EXPECT_EQ(all.num_with_depth, size_t(kWidth * kHeight / 2));
  EXPECT_EQ(all.num_compared, size_t(kWidth / 2 * (kHeight - 10)));  // not the sky
  EXPECT_DOUBLE_EQ(all.coverage, 0.5);
  // |N(0, 5 mm)|: median 3.4 mm, 90 % 8.2 mm; the 2 % at 0.5 m set the 99 % quantile and the bias.
  EXPECT_NEAR(all.median_abs_error_m, 0.0034, 0.0006);
  EXPECT_NEAR(all.p90_abs_error_m, 0.0082, 0.0012);
  EXPECT_GT(all.p99_abs_error_m, 0.45);
  EXPECT_NEAR(all.mean_error_m, 0.02 * 0.5, 0.004);
  EXPECT_NEAR(all.within_5cm, 0.98, 0.01);
  EXPECT_NEAR(all.median_abs_relative_error, 0.0034 / 4, 0.0003);
  EXPECT_FALSE(evaluation.abs_error_sample.empty());
}

TEST_F(DenseDepthEvaluationTest,
       SkipsATrueDepthMapOfAnotherSizeAndRefusesAFolderThatIsNoWorkspace) {
  Write(0.005);
  colmap::mvs::DepthMap small(kWidth / 2, kHeight, 0.f, 10.f);
  small.Write(dir_.File("truth/000.bin"));
  const DenseDepthEvaluation evaluation =
      EvaluateDenseDepth(dir_.File("dense"), dir_.File("truth"));
  EXPECT_TRUE(evaluation.image_names.empty());
  ASSERT_EQ(evaluation.images_of_another_size.size(), 1u);
  EXPECT_EQ(evaluation.images_of_another_size[0], "left/000.png");
  EXPECT_EQ(evaluation.all.num_compared, 0u);
  try {
    EvaluateDenseDepth(dir_.File("truth"), dir_.File("truth"));
    FAIL() << "a folder without fusion.cfg was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("fusion.cfg"), std::string::npos) << error.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir_.File("truth/stereo")));  // nothing created there
}

}  // namespace
}  // namespace colmap_lidar
