// Whether the joint adjustment's association rounds settled. Each round re-associates the LiDAR
// points and planes (ICP-like) and solves again; the rounds end when one moves cam_from_lidar by
// less than round_convergence_deg / round_convergence_mm, or at max_association_rounds. Ended by
// that cap while T_e still moves, the result depends on where the rounds stopped; on an axis whose
// last move exceeds half its reported sigma that dependence is larger than the uncertainty the
// sigma claims, and it is said.
#pragma once

#include "bridge/joint/joint_adjuster.h"

#include <array>
#include <string>
#include <vector>

namespace colmap_lidar {

struct AssociationSettling {
  bool settled = true;
  int rounds = 0;
  // The last round's move per camera axis (rx ry rz [deg], tx ty tz [mm]) and the same in reported
  // sigmas (NaN on an undetermined axis or without an uncertainty).
  std::array<double, 6> last_move{};
  std::array<double, 6> last_move_sigmas{};
  // One line per determined axis whose last move exceeds half its sigma, if the rounds did not
  // settle; empty otherwise.
  std::vector<std::string> warnings;
};

AssociationSettling CheckAssociationSettling(const JointAdjustmentSummary& summary);

}  // namespace colmap_lidar
