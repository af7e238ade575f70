#include "lidar/pose_graph.h"

#include "lidar/relative_pose_error.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>

namespace colmap_lidar {
namespace {

Eigen::Isometry3d Pose(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  pose.translation() = t;
  return pose;
}

double RotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() * 180 / M_PI;
}

TEST(RelativePoseError, ZeroAtTheTruthTwoSigmaForOneCentimetreAndAutodiffMatchesNumeric) {
  const Eigen::Isometry3d world_from_i = Pose(0.7, {0.2, -0.9, 0.4}, {0.3, -0.2, 1.9});
  const Eigen::Isometry3d world_from_j = Pose(-1.2, {0.7, 0.3, -0.5}, {-0.8, 0.4, 2.4});
  const Eigen::Isometry3d i_from_j = world_from_i.inverse() * world_from_j;
  Eigen::Quaterniond q_i(world_from_i.linear()), q_j(world_from_j.linear());
  Eigen::Vector3d t_i = world_from_i.translation(), t_j = world_from_j.translation();
  std::vector<double*> blocks = {q_i.coeffs().data(), t_i.data(), q_j.coeffs().data(), t_j.data()};
  const Eigen::Matrix<double, 6, 6> w = DiagonalSqrtInformation(0.001, 0.005);
  double residuals[6];
  std::unique_ptr<ceres::CostFunction> exact(RelativePoseError::Create(i_from_j, w));
  ASSERT_TRUE(exact->Evaluate(blocks.data(), residuals, nullptr));
  for (const double r : residuals) EXPECT_NEAR(r, 0, 1e-9);

  // The measurement 1 cm off along y of the target frame: 2 sigma on that axis.
  Eigen::Isometry3d shifted = i_from_j;
  shifted.translation() += Eigen::Vector3d(0, 0.01, 0);
  std::unique_ptr<ceres::CostFunction> off_by_1cm(RelativePoseError::Create(shifted, w));
  ASSERT_TRUE(off_by_1cm->Evaluate(blocks.data(), residuals, nullptr));
  EXPECT_NEAR(residuals[4], -2.0, 1e-6);

  // Gradients where every residual is far from zero, with a full (non-diagonal) whitening.
  Eigen::Matrix<double, 6, 6> full = Eigen::Matrix<double, 6, 6>::Random();
  full = (full * full.transpose() + Eigen::Matrix<double, 6, 6>::Identity()).eval();
  std::unique_ptr<ceres::CostFunction> far(RelativePoseError::Create(
      Pose(0.05, {0.3, 0.4, -0.2}, {0.02, -0.01, 0.03}) * i_from_j, full));
  const std::vector<const ceres::Manifold*> manifolds(4, nullptr);
  ceres::GradientChecker checker(far.get(), &manifolds, ceres::NumericDiffOptions());
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(blocks.data(), 1e-6, &results)) << results.error_log;
}

// Six poses on a ring, every neighbour and every second neighbour measured with noise: the tree alone
// accumulates the noise of its path; the refinement over all edges spreads it.
TEST(SolvePoseGraph, RefinementOverLoopsBeatsTheSpanningTreeAndKeepsTheGauge) {
  const size_t n = 6;
  std::vector<Eigen::Isometry3d> truth;
  for (size_t k = 0; k < n; ++k) {
    const double angle = 2 * M_PI * k / n;
    truth.push_back(Pose(
        angle + 0.1 * k, {0.1, 0.2, 1.0}, {3 * std::cos(angle), 3 * std::sin(angle), 0.1 * k}));
  }
  const Eigen::Isometry3d gauge = truth[0];
  for (Eigen::Isometry3d& pose : truth) pose = gauge.inverse() * pose;  // node 0 is the world
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 1);
  const double sigma_rotation = 0.002, sigma_translation = 0.01;
  std::vector<RelativePoseEdge> edges;
  for (size_t i = 0; i < n; ++i) {
    for (const size_t step : {1, 2}) {
      const size_t j = (i + step) % n;
      const Eigen::Vector3d w(noise(rng), noise(rng), noise(rng));
      const Eigen::Vector3d t(noise(rng), noise(rng), noise(rng));
      Eigen::Isometry3d measured = truth[i].inverse() * truth[j];
      measured = Pose(sigma_rotation * w.norm(), w, sigma_translation * t) * measured;
      edges.push_back({i,
                       j,
                       measured,
                       step == 1 ? 2.0 : 1.0,
                       DiagonalSqrtInformation(sigma_rotation, sigma_translation)});
    }
  }
  PoseGraphOptions tree_only;
  tree_only.refine = false;
  const PoseGraphSolution tree = SolvePoseGraph(n, edges, tree_only);
  const PoseGraphSolution refined = SolvePoseGraph(n, edges, PoseGraphOptions());
  EXPECT_EQ(refined.num_components, 1);
  double tree_error = 0, refined_error = 0;
  for (size_t k = 0; k < n; ++k) {
    tree_error += (tree.world_from_node[k].translation() - truth[k].translation()).norm();
    refined_error += (refined.world_from_node[k].translation() - truth[k].translation()).norm();
    EXPECT_LT(RotationErrorDeg(refined.world_from_node[k], truth[k]), 0.3);
  }
  std::cout << "mean position error: tree " << 1000 * tree_error / n << " mm, refined "
            << 1000 * refined_error / n << " mm" << std::endl;
  EXPECT_LT(refined_error, 0.5 * tree_error);  // measured 0.31
  EXPECT_LT(refined_error / n, 0.02);
  EXPECT_TRUE(refined.world_from_node[0].isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  EXPECT_LT(refined.final_cost, refined.initial_cost);
}

TEST(SolvePoseGraph, ComponentsGetTheirOwnGaugeAndABadEdgeIsRefused) {
  const Eigen::Isometry3d a_from_b = Pose(0.3, {0, 0, 1}, {1, 0, 0});
  const std::vector<RelativePoseEdge> edges = {{0, 1, a_from_b, 1.0, {}},
                                               {2, 3, a_from_b, 1.0, {}}};
  const PoseGraphSolution solution = SolvePoseGraph(5, edges, PoseGraphOptions());
  EXPECT_EQ(solution.num_components, 3);
  EXPECT_EQ(solution.component, (std::vector<int>{0, 0, 1, 1, 2}));
  EXPECT_TRUE(solution.world_from_node[1].isApprox(a_from_b, 1e-9));
  EXPECT_TRUE(solution.world_from_node[2].isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  EXPECT_TRUE(solution.world_from_node[3].isApprox(a_from_b, 1e-9));
  EXPECT_THROW(SolvePoseGraph(2, {{0, 2, a_from_b, 1.0, {}}}, PoseGraphOptions()),
               std::invalid_argument);
  PoseGraphOptions bad;
  bad.loss = RobustLoss::kNone;
  EXPECT_FALSE(bad.Check());
  EXPECT_THROW(SolvePoseGraph(2, edges, bad), std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
