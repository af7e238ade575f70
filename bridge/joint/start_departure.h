// Do no harm: how far the joint adjustment moved cam_from_lidar from its start, per camera axis,
// against what the start's own uncertainty allows. With a prior (rig.json's guess with a sigma) an
// axis may move 3 of the prior's sigmas; a start without one (a guess without sigma, a hand-eye, the travel direction and the
// structure) allows 2 deg / 100 mm, about what such starts are off by. An axis the adjustment held
// (undetermined) is not judged: it stays at the start. A move beyond the allowance is not an error
// (the data may know better than the start) but is said, with the evidence: how far each
// association round moved cam_from_lidar, and the data groups' estimated sigmas.
#pragma once

#include "bridge/joint/joint_adjuster.h"

#include "colmap/geometry/rigid3.h"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace colmap_lidar {

struct StartDeparture {
  // rx ry rz [deg] (rotation vector of result * inverse(start) about the camera axes), tx ty tz [mm]
  std::array<double, 6> move{};
  std::array<double, 6> allowed{};
  std::array<bool, 6> beyond{};  // determined axes that moved beyond `allowed`
  // One line per axis beyond its allowance, with the evidence; empty: none.
  std::vector<std::string> warnings;
};

// rx ry rz [deg] (rotation vector of `to` * inverse(`from`) about the camera axes), tx ty tz [mm].
std::array<double, 6> ExtrinsicAxisMove(const colmap::Rigid3d& from, const colmap::Rigid3d& to);

// `data`: its prior on cam_from_lidar (ExtrinsicMeasurement::prior; covariance in rad and m about
// and along the camera axes), if any, gives the start's sigma per axis.
StartDeparture CheckStartDeparture(const colmap::Rigid3d& start,
                                   const colmap::Rigid3d& result,
                                   const JointProblemData& data,
                                   const JointAdjustmentSummary& summary);

}  // namespace colmap_lidar
