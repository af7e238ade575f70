#include "bridge/joint/association_settling.h"

#include <cmath>
#include <limits>
#include <sstream>

namespace colmap_lidar {
namespace {

constexpr const char* kAxisNames[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};
// A last move beyond this many sigmas makes the stopping point matter.
constexpr double kMaxSettledMoveSigmas = 0.5;

}  // namespace

AssociationSettling CheckAssociationSettling(const JointAdjustmentSummary& summary) {
  AssociationSettling settling;
  settling.settled = summary.association_settled;
  settling.rounds = static_cast<int>(summary.extrinsic_change_per_round.size());
  settling.last_move = summary.last_round_move;
  const ExtrinsicUncertainty& uncertainty = summary.uncertainty;
  for (int k = 0; k < 6; ++k) {
    const double sigma = std::sqrt(uncertainty.covariance(k, k));
    const bool judged = uncertainty.computed && !uncertainty.undetermined[k] && sigma > 0;
    settling.last_move_sigmas[k] =
        judged ? settling.last_move[k] / sigma : std::numeric_limits<double>::quiet_NaN();
    if (settling.settled || !judged ||
        std::abs(settling.last_move_sigmas[k]) <= kMaxSettledMoveSigmas) {
      continue;
    }
    std::ostringstream line;
    line.precision(3);
    line << kAxisNames[k] << " still moved " << settling.last_move[k] << (k < 3 ? " deg" : " mm")
         << " (" << settling.last_move_sigmas[k] << " sigma) in the last of " << settling.rounds
         << " association rounds, which ended at the round limit: the result on this axis depends "
            "on where the rounds stopped by more than half its sigma";
    settling.warnings.push_back(line.str());
  }
  return settling;
}

}  // namespace colmap_lidar
