// Is the reported uncertainty of cam_from_lidar calibrated? Over seeded independent noise draws of a
// small synthetic joint problem (keypoints with Gaussian pixel noise, depth priors with noise of their
// own sigma_d, a common stereo scale error and a common disparity bias field drawn with the sigmas
// the adjuster assumes for them, LiDAR with 1 cm range noise;
// tests/testing/synthetic_joint_problem.h), the true error must lie within 2 reported sigma about
// 95 % of the time on every axis (rotation about the camera axes, translation along them).
// The test prints the coverage of the formal covariance (no clusters, no consider terms) beside
// it: without the consider terms it misses the common stereo errors along the camera's z axis; the
// rotation axes fail if the manifold's tangent is read as a rotation vector (half the angle).
#include "bridge/joint/joint_adjuster.h"
#include "tests/testing/synthetic_joint_problem.h"

#include <gtest/gtest.h>

#include <array>
#include <iomanip>
#include <iostream>
#include <random>

namespace colmap_lidar {
namespace {

constexpr int kNumDraws = 50;

JointAdjusterOptions CoverageOptions() {
  JointAdjusterOptions options;
  options.sigma_lidar_m = 0.01;
  options.num_association_rounds = 2;
  options.association.num_samples = 500;
  return options;
}

TEST(JointAdjusterCoverageTest, TwoSigmaCoverageOfEveryExtrinsicAxisIsAbout95Percent) {
  const sim::Scene scene = sim::Scene::Create("t_specimen");
  std::array<int, 6> covered_formal{}, covered{};
  std::array<double, 6> sum_squared_z{};
  static const char* kAxes[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};
  const JointAdjusterOptions options = CoverageOptions();
  std::mt19937 rng(77);
  std::normal_distribution<double> scale_error(0, options.observability.stereo_scale_sigma);
  std::normal_distribution<double> disparity_error(0,
                                                   options.observability.disparity_bias_sigma_px);
  for (int draw = 0; draw < kNumDraws; ++draw) {
    testing::SyntheticJointOptions synthetic;
    synthetic.depth_scale_error = scale_error(rng);
    synthetic.disparity_bias_px = {
        disparity_error(rng), disparity_error(rng), disparity_error(rng)};
    synthetic.num_stations = 6;
    synthetic.lidar_points = 60000;
    synthetic.lidar_range_noise_m = 0.01;
    synthetic.pixel_noise = 0.5;
    synthetic.depth_noise_sigmas = 1.0;
    synthetic.landmark_stride = 6;
    synthetic.noise_seed = 1000 + draw;
    auto problem = testing::MakeSyntheticJointProblem(scene, synthetic);
    colmap::Rigid3d cam_from_lidar = problem->cam_from_lidar;
    const JointAdjustmentSummary summary =
        JointAdjuster(options).Run(problem->data, &problem->reconstruction, &cam_from_lidar);
    ASSERT_TRUE(summary.uncertainty.computed) << summary.uncertainty.message;
    ASSERT_TRUE(summary.uncertainty.cluster_robust);
    const Eigen::Matrix<double, 6, 1> error =
        testing::ExtrinsicError(cam_from_lidar, problem->true_cam_from_lidar);
    std::cout << "draw " << draw << " error/sigma:";
    for (int axis = 0; axis < 6; ++axis) {
      const double sigma = std::sqrt(summary.uncertainty.covariance(axis, axis));
      const double formal_sigma = std::sqrt(summary.uncertainty.formal_covariance(axis, axis));
      const double z = error[axis] / sigma;
      covered[axis] += std::abs(z) <= 2;
      covered_formal[axis] += std::abs(error[axis]) <= 2 * formal_sigma;
      sum_squared_z[axis] += z * z;
      std::cout << " " << kAxes[axis] << " " << std::setprecision(2) << z;
    }
    std::cout << std::endl;
  }
  for (int axis = 0; axis < 6; ++axis) {
    const double coverage = static_cast<double>(covered[axis]) / kNumDraws;
    std::cout << kAxes[axis] << ": 2-sigma coverage " << 100 * coverage << " % (formal "
              << 100.0 * covered_formal[axis] / kNumDraws << " %), rms error/sigma "
              << std::sqrt(sum_squared_z[axis] / kNumDraws) << std::endl;
    EXPECT_GE(coverage, 0.85) << kAxes[axis];
    EXPECT_LE(coverage, 0.99) << kAxes[axis];
  }
}

}  // namespace
}  // namespace colmap_lidar
