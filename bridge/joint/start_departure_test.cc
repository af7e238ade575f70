#include "bridge/joint/start_departure.h"

#include <gtest/gtest.h>

#include <cmath>

namespace colmap_lidar {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

colmap::Rigid3d Moved(double rx_deg, const Eigen::Vector3d& translation_m) {
  colmap::Rigid3d moved;
  moved.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(rx_deg * kDegToRad, Eigen::Vector3d::UnitX()));
  moved.translation = translation_m;
  return moved;
}

TEST(StartDepartureTest, WithoutAPriorTwoDegreesAndTenCentimetresAreAllowed) {
  JointAdjustmentSummary summary;
  summary.extrinsic_change_per_round = {{2.5, 30}, {0.2, 50}};
  const StartDeparture small = CheckStartDeparture(
      colmap::Rigid3d(), Moved(1.5, Eigen::Vector3d(0, 0.09, 0)), JointProblemData(), summary);
  EXPECT_TRUE(small.warnings.empty());
  EXPECT_NEAR(small.move[0], 1.5, 1e-9);
  EXPECT_NEAR(small.move[4], 90, 1e-9);
  const StartDeparture large = CheckStartDeparture(
      colmap::Rigid3d(), Moved(2.5, Eigen::Vector3d(0, 0, 0.2)), JointProblemData(), summary);
  ASSERT_EQ(large.warnings.size(), 2u);
  EXPECT_TRUE(large.beyond[0] && large.beyond[5]);
  EXPECT_NE(large.warnings[0].find("rx moved 2.5 deg"), std::string::npos) << large.warnings[0];
  EXPECT_NE(large.warnings[0].find("round 1 of 2 moved it most"), std::string::npos);
}

TEST(StartDepartureTest, APriorAllowsThreeOfItsSigmasAndHeldAxesAreNotJudged) {
  JointProblemData data;
  ExtrinsicMeasurement prior;
  prior.prior = true;
  prior.covariance.diagonal() << std::pow(0.1 * kDegToRad, 2), std::pow(0.1 * kDegToRad, 2),
      std::pow(0.1 * kDegToRad, 2), 1e-4, 1e-4, 1e-4;  // 0.1 deg, 10 mm
  data.extrinsic_measurements.push_back(prior);
  JointAdjustmentSummary summary;
  summary.uncertainty.undetermined[5] = true;
  const StartDeparture departure = CheckStartDeparture(
      colmap::Rigid3d(), Moved(0.4, Eigen::Vector3d(0.02, 0, 0.5)), data, summary);
  EXPECT_NEAR(departure.allowed[0], 0.3, 1e-9);
  EXPECT_NEAR(departure.allowed[3], 30, 1e-9);
  EXPECT_TRUE(departure.beyond[0]);
  EXPECT_FALSE(departure.beyond[3]);
  EXPECT_FALSE(departure.beyond[5]);  // held: undetermined
  EXPECT_EQ(departure.warnings.size(), 1u);
}

}  // namespace
}  // namespace colmap_lidar
