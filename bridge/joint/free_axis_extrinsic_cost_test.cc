#include "bridge/joint/free_axis_extrinsic_cost.h"

#include "bridge/joint/lidar_pair_cost.h"
#include "tests/testing/generic_poses.h"
#include "tests/testing/gradient_check.h"

#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>

namespace colmap_lidar {
namespace {

const Eigen::Vector3d kAxis = Eigen::Vector3d(0.1, -0.2, 1.0).normalized();

// A LiDAR pair block (compressed, 200 observations) around generic poses, residuals of centimetres.
struct PairBlock : testing::GenericStationPair {
  std::vector<PointToPlaneObservation> observations;
  double angle = 0.3;

  PairBlock() {
    std::mt19937 rng(11);
    std::normal_distribution<double> normal(0, 1);
    for (int k = 0; k < 200; ++k) {
      observations.push_back({Eigen::Vector3d(8 * normal(rng), 8 * normal(rng), normal(rng)),
                              Eigen::Vector3d(8 * normal(rng), 8 * normal(rng), normal(rng)),
                              Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized()});
    }
  }
  ceres::CostFunction* Inner() const {
    return LidarPairPointToPlaneCost::Create(observations, 0.02);
  }
  std::vector<double*> Blocks() {
    std::vector<double*> blocks = GenericStationPair::Blocks();
    blocks.push_back(&angle);
    return blocks;
  }
};

double Cost(const ceres::CostFunction& cost, std::vector<double*> blocks) {
  Eigen::VectorXd residuals(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(blocks.data(), residuals.data(), nullptr));
  return residuals.squaredNorm();
}

TEST(FreeAxisExtrinsicCost, EqualsTheInnerCostAtTheTurnedExtrinsic) {
  PairBlock setup;
  std::unique_ptr<ceres::CostFunction> wrapped(FreeAxisExtrinsicCost::Create(setup.Inner(), kAxis));
  std::unique_ptr<ceres::CostFunction> inner(setup.Inner());
  const double wrapped_cost = Cost(*wrapped, setup.Blocks());
  setup.cam_from_lidar = colmap::Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(setup.angle, kAxis)),
                                         Eigen::Vector3d::Zero()) *
                         setup.cam_from_lidar;
  const double inner_cost = Cost(*inner, setup.GenericStationPair::Blocks());
  EXPECT_GT(inner_cost, 1.0);
  EXPECT_NEAR(wrapped_cost, inner_cost, 1e-9 * inner_cost);
}

// The cost cannot tell T_e's rotation about the axis from its own angle; about another axis it can.
TEST(FreeAxisExtrinsicCost, TurningTheExtrinsicAboutTheAxisIsUndoneByTheAngle) {
  std::unique_ptr<ceres::CostFunction> wrapped(
      FreeAxisExtrinsicCost::Create(PairBlock().Inner(), kAxis));
  for (const bool about_axis : {true, false}) {
    PairBlock setup;
    const double before = Cost(*wrapped, setup.Blocks());
    const Eigen::Vector3d axis =
        about_axis ? kAxis : kAxis.cross(Eigen::Vector3d::UnitX()).normalized();
    const colmap::Rigid3d turn(Eigen::Quaterniond(Eigen::AngleAxisd(0.05, axis)),
                               Eigen::Vector3d::Zero());
    setup.cam_from_lidar = turn * setup.cam_from_lidar;
    setup.angle -= 0.05;
    const double after = Cost(*wrapped, setup.Blocks());
    if (about_axis) {
      EXPECT_NEAR(after, before, 1e-9 * before);
    } else {
      EXPECT_GT(std::abs(after - before), 1e-3 * before);  // measured 2.7e-3
    }
  }
}

TEST(FreeAxisExtrinsicCost, GradientCheckerAcceptsTheChainedJacobians) {
  PairBlock setup;
  std::unique_ptr<ceres::CostFunction> cost(FreeAxisExtrinsicCost::Create(setup.Inner(), kAxis));
  ASSERT_EQ(cost->parameter_block_sizes().size(), 7u);
  ceres::EigenQuaternionManifold quaternion;
  const std::vector<const ceres::Manifold*> manifolds = {
      &quaternion, nullptr, &quaternion, nullptr, &quaternion, nullptr, nullptr};
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(
      testing::GradientMatchesNumericDifferences(*cost, setup.Blocks(), manifolds, &results));
  EXPECT_LT(results.maximum_relative_error, 1e-7);
}

TEST(FreeAxisExtrinsicCost, RefusesAnInnerCostWithoutTheExtrinsicLast) {
  PairBlock setup;
  // Only a translation block last: not a cam_from_lidar pair.
  class Plain : public ceres::CostFunction {
   public:
    Plain() {
      mutable_parameter_block_sizes()->push_back(3);
      set_num_residuals(1);
    }
    bool Evaluate(double const* const*, double* residuals, double**) const override {
      residuals[0] = 0;
      return true;
    }
  };
  EXPECT_ANY_THROW(FreeAxisExtrinsicCost(new Plain, kAxis));
  EXPECT_ANY_THROW(FreeAxisExtrinsicCost(setup.Inner(), Eigen::Vector3d::Zero()));
}

}  // namespace
}  // namespace colmap_lidar
