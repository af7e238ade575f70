#include "lidar/model_evaluation.h"

#include <gtest/gtest.h>

#include <random>

namespace colmap_lidar {
namespace {

// Samples of an open box (5 faces) of 0.6 x 0.4 x 0.8 m on a grid of `spacing`, with outward normals.
PointCloud BoxSurface(double spacing) {
  PointCloud cloud;
  const Eigen::Vector3d half(0.3, 0.2, 0.4);
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = static_cast<int>(2 * half[u] / spacing),
              nv = static_cast<int>(2 * half[v] / spacing);
    for (const double side : {-1.0, 1.0}) {
      if (axis == 2 && side < 0) continue;  // the bottom rests on the ground
      for (int a = 0; a < nu; ++a) {
        for (int b = 0; b < nv; ++b) {
          Eigen::Vector3d p;
          p[axis] = side * half[axis];
          p[u] = -half[u] + (a + 0.5) * 2 * half[u] / nu;
          p[v] = -half[v] + (b + 0.5) * 2 * half[v] / nv;
          Eigen::Vector3d n = Eigen::Vector3d::Zero();
          n[axis] = side;
          cloud.points.push_back(p);
          cloud.normals.push_back(n);
        }
      }
    }
  }
  return cloud;
}

TEST(ModelEvaluationTest, TruthAgainstItselfIsExact) {
  const PointCloud truth = BoxSurface(0.005);
  const ModelEvaluation result = EvaluateModel(truth, truth, ModelEvaluationOptions());
  EXPECT_EQ(result.num_evaluated, truth.Size());
  EXPECT_LT(result.mean, 1e-9);
  EXPECT_LT(result.max, 1e-9);
  ASSERT_EQ(result.at_thresholds.size(), 3u);
  EXPECT_DOUBLE_EQ(result.at_thresholds[0].completeness, 1.0);
  EXPECT_DOUBLE_EQ(result.at_thresholds[0].f_score, 1.0);
  // A 5 mm grid has 4 points per cm^2.
  EXPECT_NEAR(result.density_points_per_cm2, 4.0, 0.05);
}

TEST(ModelEvaluationTest, KnownOffsetsAndNoiseAreMeasured) {
  const PointCloud truth = BoxSurface(0.005);
  ModelEvaluationOptions options;
  options.align_icp = false;
  // Every point pushed 3 mm outwards, on a denser, differently placed grid.
  PointCloud model = BoxSurface(0.0035);
  for (size_t i = 0; i < model.Size(); ++i) model.points[i] += 0.003 * model.normals[i];
  ModelEvaluation result = EvaluateModel(model, truth, options);
  EXPECT_NEAR(result.mean, 0.003, 1e-4);
  EXPECT_NEAR(result.median, 0.003, 1e-5);
  EXPECT_NEAR(result.at_thresholds[0].precision, 0.0, 0.02);  // 2 mm: nothing within
  EXPECT_NEAR(result.at_thresholds[1].precision, 1.0, 1e-9);  // 5 mm: everything
  // A 3.5 mm grid: 1 / 0.35^2 = 8.2 points per cm^2.
  EXPECT_NEAR(result.density_points_per_cm2, 1 / (0.35 * 0.35), 0.4);

  // Gaussian noise of 2 mm along the normal: E|N(0, s)| = s sqrt(2/pi).
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.002);
  model = BoxSurface(0.003);
  for (size_t i = 0; i < model.Size(); ++i) model.points[i] += noise(rng) * model.normals[i];
  result = EvaluateModel(model, truth, options);
  EXPECT_NEAR(result.mean, 0.002 * std::sqrt(2 / M_PI), 1e-4);
  EXPECT_NEAR(result.rmse, 0.002, 1.5e-4);
}

TEST(ModelEvaluationTest, IcpRemovesARigidMisalignmentAndReportsIt) {
  const PointCloud truth = BoxSurface(0.005);
  const Eigen::Isometry3d model_from_truth =
      Eigen::Translation3d(0.012, -0.008, 0.01) *
      Eigen::AngleAxisd(1.0 * M_PI / 180, Eigen::Vector3d(0.3, 1, 0.2).normalized());
  PointCloud model = BoxSurface(0.004);
  for (Eigen::Vector3d& p : model.points) p = model_from_truth * p;
  ModelEvaluationOptions options;
  const ModelEvaluation aligned = EvaluateModel(model, truth, options);
  EXPECT_TRUE(aligned.icp_converged);
  EXPECT_LT(aligned.mean, 5e-5);
  const Eigen::Isometry3d residual = aligned.truth_from_model * model_from_truth;
  EXPECT_LT(residual.translation().norm(), 1e-4);
  EXPECT_LT(Eigen::AngleAxisd(residual.linear()).angle(), 1e-4);
  options.align_icp = false;
  EXPECT_GT(EvaluateModel(model, truth, options).mean, 0.004);
}

TEST(ModelEvaluationTest, PointsAwayFromTheStructureAreCropped) {
  const PointCloud truth = BoxSurface(0.005);
  PointCloud model = truth;
  model.normals.clear();
  model.points.emplace_back(3, 3, 0);  // ground / background
  const ModelEvaluation result = EvaluateModel(model, truth, ModelEvaluationOptions());
  EXPECT_EQ(result.num_evaluated, truth.Size());
  EXPECT_LT(result.max, 1e-9);
}

TEST(ModelEvaluationTest, RejectsBadInput) {
  const PointCloud truth = BoxSurface(0.01);
  EXPECT_THROW(EvaluateModel(PointCloud(), truth, ModelEvaluationOptions()), std::invalid_argument);
  PointCloud no_normals = truth;
  no_normals.normals.clear();
  EXPECT_THROW(EvaluateModel(truth, no_normals, ModelEvaluationOptions()), std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
