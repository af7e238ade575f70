#include "lidar/frame_to_map_icp.h"

#include "tests/testing/ray_cast_street.h"

#include <gtest/gtest.h>

namespace colmap_lidar {
namespace {

// Points beyond the platform's own returns.
std::vector<Eigen::Vector3d> InRange(const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> kept;
  for (const Eigen::Vector3d& p : points) {
    if (p.norm() > 2.0) kept.push_back(p);
  }
  return kept;
}

// A map of one HDL-64-like sweep of the ray-cast street and a second sweep `motion_m` farther down
// the street, registered from rest with the odometry's first threshold (tau 6 m): the residuals
// must not follow the scanner's rings and scan lines on the ground and the facades, which a
// platform moving along them sees where it saw them before.
TEST(FrameToMapIcp, FindsTheMotionAlongAStreetFromRest) {
  const std::vector<testing::Box> street = testing::StreetBoxes(1, 100);
  std::mt19937 rng(1);
  for (const double motion_m : {0.6, 1.2}) {
    const double speed = motion_m / 0.5;  // frozen sweeps at t = 0 and t = 0.5 s
    const auto first = InRange(testing::ScanSweep(street,
                                                  0,
                                                  1e-9,
                                                  speed,
                                                  64,
                                                  1800,
                                                  0.01,
                                                  &rng,
                                                  /*top_deg=*/2,
                                                  /*bottom_deg=*/-24.8));
    const auto second =
        InRange(testing::ScanSweep(street, 0.5, 1e-9, speed, 64, 1800, 0.01, &rng, 2, -24.8));
    const Eigen::Isometry3d truth =
        testing::DrivePose(0, speed).inverse() * testing::DrivePose(0.5, speed);
    VoxelHashMap map(1.0, 100, 20);
    map.Update(FirstPointPerVoxel(first, 0.5), Eigen::Vector3d::Zero());
    const FrameToMapIcpResult result =
        AlignFrameToMap(FirstPointPerVoxel(FirstPointPerVoxel(second, 0.5), 1.5),
                        &map,
                        Eigen::Isometry3d::Identity(),
                        6.0,
                        2.0 / 3.0,
                        FrameToMapIcpOptions());
    const double error = (result.world_from_lidar.translation() - truth.translation()).norm();
    std::cout << "motion " << motion_m << " m: found "
              << result.world_from_lidar.translation().transpose() << ", error " << error << " m"
              << std::endl;
    // Measured 0.036 m (0.6 m) and 0.003 m (1.2 m); residuals on the sparse far surfaces stop
    // at 0.31 m and 0.12 m.
    EXPECT_LT(error, 0.1) << motion_m;
    EXPECT_TRUE(result.converged);
  }
}

TEST(FrameToMapIcp, RefusesANonPositiveThreshold) {
  VoxelHashMap map(1.0, 100, 20);
  map.Update({Eigen::Vector3d(1, 0, 0)}, Eigen::Vector3d::Zero());
  EXPECT_THROW(AlignFrameToMap({Eigen::Vector3d(1, 0, 0)},
                               &map,
                               Eigen::Isometry3d::Identity(),
                               0,
                               1,
                               FrameToMapIcpOptions()),
               std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
