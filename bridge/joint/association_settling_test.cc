#include "bridge/joint/association_settling.h"

#include <gtest/gtest.h>

#include <cmath>

namespace colmap_lidar {
namespace {

// Sigmas 0.01 deg and 10 mm on every axis; tz undetermined.
JointAdjustmentSummary SummaryWithSigmas() {
  JointAdjustmentSummary summary;
  summary.uncertainty.computed = true;
  summary.uncertainty.covariance.diagonal() << 1e-4, 1e-4, 1e-4, 100, 100, 0;
  summary.uncertainty.undetermined[5] = true;
  summary.extrinsic_change_per_round.assign(10, {0.02, 30});
  summary.last_round_move = {0.001, -0.008, 0, 24, -3, 90};
  return summary;
}

TEST(AssociationSettlingTest, RoundsEndedByTheLimitNameTheAxesThatStillMoveBeyondHalfASigma) {
  JointAdjustmentSummary summary = SummaryWithSigmas();
  summary.association_settled = false;
  const AssociationSettling settling = CheckAssociationSettling(summary);
  EXPECT_FALSE(settling.settled);
  EXPECT_EQ(settling.rounds, 10);
  EXPECT_NEAR(settling.last_move_sigmas[3], 2.4, 1e-9);
  EXPECT_NEAR(settling.last_move_sigmas[1], -0.8, 1e-9);
  EXPECT_TRUE(std::isnan(settling.last_move_sigmas[5]));  // undetermined: no sigma
  ASSERT_EQ(settling.warnings.size(), 2u);                // ry (0.8 sigma) and tx (2.4)
  EXPECT_EQ(settling.warnings[0].rfind("ry still moved", 0), 0u) << settling.warnings[0];
  EXPECT_EQ(settling.warnings[1].rfind("tx still moved 24 mm (2.4 sigma)", 0), 0u)
      << settling.warnings[1];
}

TEST(AssociationSettlingTest, SettledRoundsWarnOfNothing) {
  const AssociationSettling settling = CheckAssociationSettling(SummaryWithSigmas());
  EXPECT_TRUE(settling.settled);
  EXPECT_TRUE(settling.warnings.empty());
  EXPECT_NEAR(settling.last_move_sigmas[3], 2.4, 1e-9);  // reported all the same
}

}  // namespace
}  // namespace colmap_lidar
