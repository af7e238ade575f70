#include "bridge/joint/lidar_pair_cost.h"

#include "bridge/joint/lidar_point_to_plane_cost.h"
#include "tests/testing/generic_poses.h"
#include "tests/testing/gradient_check.h"

#include "colmap/geometry/rigid3.h"

#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>

namespace colmap_lidar {
namespace {

// Generic poses and random observations around them.
struct PairSetup : testing::GenericStationPair {
  std::vector<PointToPlaneObservation> observations;

  explicit PairSetup(int num_observations) {
    std::mt19937 rng(5);
    std::normal_distribution<double> normal(0, 1);
    const auto random_vector = [&]() {
      return Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    };
    for (int k = 0; k < num_observations; ++k) {
      observations.push_back(
          {2 * random_vector(), 2 * random_vector(), random_vector().normalized()});
    }
  }
};

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Jacobians in the tangent space of Ceres' EigenQuaternionManifold (what the solver uses).
std::vector<RowMajor> TangentJacobians(const ceres::CostFunction& cost,
                                       const std::vector<double*>& blocks,
                                       Eigen::VectorXd* residuals) {
  const int rows = cost.num_residuals();
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  std::vector<RowMajor> ambient;
  std::vector<double*> pointers;
  for (const int size : sizes) ambient.emplace_back(rows, size);
  for (RowMajor& jacobian : ambient) pointers.push_back(jacobian.data());
  residuals->resize(rows);
  EXPECT_TRUE(cost.Evaluate(blocks.data(), residuals->data(), pointers.data()));
  std::vector<RowMajor> tangent;
  for (size_t b = 0; b < sizes.size(); ++b) {
    if (sizes[b] != 4) {
      tangent.push_back(ambient[b]);
      continue;
    }
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus;
    ceres::EigenQuaternionManifold().PlusJacobian(blocks[b], plus.data());
    tangent.push_back(ambient[b] * plus);
  }
  return tangent;
}

TEST(LidarPairCost, ResidualsAndTangentJacobiansEqualTheAutodiffFunctorPerObservation) {
  PairSetup setup(7);
  const double sigma = 0.02;
  std::unique_ptr<ceres::CostFunction> pair(
      LidarPairPointToPlaneCost::Create(setup.observations, sigma));
  Eigen::VectorXd pair_residuals;
  const std::vector<RowMajor> pair_jacobians =
      TangentJacobians(*pair, setup.Blocks(), &pair_residuals);
  for (int k = 0; k < 7; ++k) {
    const PointToPlaneObservation& o = setup.observations[k];
    std::unique_ptr<ceres::CostFunction> single(LidarPointToPlaneCostFunctor::Create(
        o.point_in_source, o.point_in_target, o.normal_in_target, sigma));
    Eigen::VectorXd residual;
    const std::vector<RowMajor> jacobians = TangentJacobians(*single, setup.Blocks(), &residual);
    EXPECT_NEAR(pair_residuals[k], residual[0], 1e-10 * (1 + std::abs(residual[0])));
    for (size_t b = 0; b < jacobians.size(); ++b) {
      EXPECT_LT((pair_jacobians[b].row(k) - jacobians[b]).norm(), 1e-9 * (1 + jacobians[b].norm()))
          << "block " << b << ", observation " << k;
    }
  }
}

// Plain (5 observations, one row each) and compressed (200 observations, 13 moment rows) forms.
class LidarPairCostGradient : public ::testing::TestWithParam<int> {};

TEST_P(LidarPairCostGradient, GradientCheckerAcceptsTheJacobianInTheQuaternionTangentSpace) {
  PairSetup setup(GetParam());
  std::unique_ptr<ceres::CostFunction> cost(
      LidarPairPointToPlaneCost::Create(setup.observations, 0.02));
  ASSERT_EQ(cost->num_residuals(),
            std::min(GetParam(), LidarPairPointToPlaneCost::kCompressedResiduals));
  ceres::EigenQuaternionManifold quaternion;
  const std::vector<const ceres::Manifold*> manifolds = {
      &quaternion, nullptr, &quaternion, nullptr, &quaternion, nullptr};
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(
      testing::GradientMatchesNumericDifferences(*cost, setup.Blocks(), manifolds, &results));
  EXPECT_LT(results.maximum_relative_error, 1e-7);
}

// Near the optimum, 20-30 m from the sensor (a real pair): the 13 moment rows cancel to a small cost
// (5 mm residuals against sigma 1 cm), which must keep its precision.
TEST(LidarPairCost, CompressedBlockKeepsItsPrecisionNearTheOptimumFarFromTheSensor) {
  testing::GenericStationPair poses;
  const colmap::Rigid3d lidar_i_from_lidar_j =
      colmap::Inverse(poses.cam_from_lidar) * poses.cam_i_from_world *
      colmap::Inverse(poses.cam_j_from_world) * poses.cam_from_lidar;
  std::mt19937 rng(9);
  std::normal_distribution<double> normal(0, 1);
  std::vector<PointToPlaneObservation> observations;
  for (int k = 0; k < 5000; ++k) {
    const Eigen::Vector3d p(25 + 3 * normal(rng), -12 + 3 * normal(rng), 2 * normal(rng));
    const Eigen::Vector3d n = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    observations.push_back({p, lidar_i_from_lidar_j * p + 0.005 * normal(rng) * n, n});
  }
  std::unique_ptr<ceres::CostFunction> plain(
      LidarPairPointToPlaneCost::Create(observations, 0.01, /*compress=*/false));
  std::unique_ptr<ceres::CostFunction> compressed(LidarPairPointToPlaneCost::Create(
      observations, 0.01, /*compress=*/true, lidar_i_from_lidar_j));
  Eigen::VectorXd r_plain, r_compressed;
  const std::vector<RowMajor> j_plain = TangentJacobians(*plain, poses.Blocks(), &r_plain);
  const std::vector<RowMajor> j_compressed =
      TangentJacobians(*compressed, poses.Blocks(), &r_compressed);
  EXPECT_NEAR(r_compressed.squaredNorm(), r_plain.squaredNorm(), 2e-13 * r_plain.squaredNorm());
  for (int b = 0; b < 6; ++b) {
    const Eigen::VectorXd gradient_plain = j_plain[b].transpose() * r_plain;
    const Eigen::VectorXd gradient = j_compressed[b].transpose() * r_compressed;
    EXPECT_LT((gradient - gradient_plain).norm(), 1e-7 * gradient_plain.norm()) << "block " << b;
  }
}

INSTANTIATE_TEST_SUITE_P(PlainAndCompressed, LidarPairCostGradient, ::testing::Values(5, 200));

TEST(LidarPairCost, ConstantBlocksGetNoJacobianAndTheOthersAreStillRight) {
  PairSetup setup(3);
  std::unique_ptr<ceres::CostFunction> cost(
      LidarPairPointToPlaneCost::Create(setup.observations, 0.05));
  Eigen::VectorXd residuals_all;
  const std::vector<RowMajor> all = TangentJacobians(*cost, setup.Blocks(), &residuals_all);
  // Only the extrinsic translation requested (the others null, as Ceres passes constant blocks).
  RowMajor translation(3, 3);
  std::vector<double*> jacobians(6, nullptr);
  jacobians[5] = translation.data();
  Eigen::VectorXd residuals(3);
  std::vector<double*> blocks = setup.Blocks();
  ASSERT_TRUE(cost->Evaluate(blocks.data(), residuals.data(), jacobians.data()));
  EXPECT_LT((residuals - residuals_all).norm(), 1e-12);
  EXPECT_LT((translation - all[5]).norm(), 1e-12);
}

// The compressed block (13 rows for 200 observations) gives Ceres the same cost, the same J^T J and
// the same J^T r as the plain block, in the manifold's tangent space, also with constant blocks.
TEST(LidarPairCost, CompressedBlockHasThePlainCostGradientAndNormalEquations) {
  PairSetup setup(200);
  // Off the optimum: residuals of a few centimetres.
  for (PointToPlaneObservation& o : setup.observations)
    o.point_in_target += 0.03 * o.normal_in_target;
  std::unique_ptr<ceres::CostFunction> plain(
      LidarPairPointToPlaneCost::Create(setup.observations, 0.02, /*compress=*/false));
  std::unique_ptr<ceres::CostFunction> compressed(
      LidarPairPointToPlaneCost::Create(setup.observations, 0.02, /*compress=*/true));
  ASSERT_EQ(plain->num_residuals(), 200);
  ASSERT_EQ(compressed->num_residuals(), LidarPairPointToPlaneCost::kCompressedResiduals);
  Eigen::VectorXd r_plain, r_compressed;
  const std::vector<RowMajor> j_plain = TangentJacobians(*plain, setup.Blocks(), &r_plain);
  const std::vector<RowMajor> j_compressed =
      TangentJacobians(*compressed, setup.Blocks(), &r_compressed);
  EXPECT_NEAR(r_compressed.squaredNorm(), r_plain.squaredNorm(), 1e-9 * r_plain.squaredNorm());
  const auto stack = [](const std::vector<RowMajor>& blocks) {
    RowMajor all(blocks[0].rows(), 18);
    for (int b = 0; b < 6; ++b) all.middleCols(3 * b, 3) = blocks[b];
    return all;
  };
  const RowMajor a = stack(j_plain), b = stack(j_compressed);
  const Eigen::MatrixXd normal_plain = a.transpose() * a;
  EXPECT_LT((b.transpose() * b - normal_plain).norm(), 1e-9 * normal_plain.norm());
  const Eigen::VectorXd gradient_plain = a.transpose() * r_plain;
  EXPECT_LT((b.transpose() * r_compressed - gradient_plain).norm(), 1e-9 * gradient_plain.norm());
  // Cost-only evaluation: the same cost.
  Eigen::VectorXd cost_only(LidarPairPointToPlaneCost::kCompressedResiduals);
  std::vector<double*> blocks = setup.Blocks();
  ASSERT_TRUE(compressed->Evaluate(blocks.data(), cost_only.data(), nullptr));
  EXPECT_NEAR(cost_only.squaredNorm(), r_plain.squaredNorm(), 1e-9 * r_plain.squaredNorm());
  // Few observations: the plain form.
  std::unique_ptr<ceres::CostFunction> small(LidarPairPointToPlaneCost::Create(
      std::vector<PointToPlaneObservation>(setup.observations.begin(),
                                           setup.observations.begin() + 10),
      0.02));
  EXPECT_EQ(small->num_residuals(), 10);
}

}  // namespace
}  // namespace colmap_lidar
