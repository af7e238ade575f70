#include "lidar/trajectory_refinement.h"

#include "lidar/cloud_io.h"
#include "tests/testing/ray_cast_street.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>

#include <random>

namespace colmap_lidar {
namespace {

// Twelve sweeps of the ray-cast street 1.2 m apart, each scanned from one pose (already
// de-skewed), written as PCD; their true poses.
std::vector<Eigen::Isometry3d> WriteStreetSweeps(const testing::ScopedTempDir& dir,
                                                 std::vector<std::string>* paths) {
  constexpr double kSpeed = 12.0, kPeriod = 0.1;
  const std::vector<testing::Box> boxes = testing::StreetBoxes(3, 12 * kSpeed * kPeriod);
  std::mt19937 rng(3);
  std::vector<Eigen::Isometry3d> truth;
  for (int k = 0; k < 12; ++k) {
    PointCloud cloud;
    cloud.points = testing::ScanSweep(boxes, k * kPeriod, 0.0, kSpeed, 32, 1440, 0.01, &rng);
    paths->push_back(dir.File("sweep" + std::to_string(k) + ".pcd"));
    WritePointCloud(paths->back(), cloud);
    truth.push_back(testing::DrivePose(k * kPeriod, kSpeed));
  }
  return truth;
}

// An odometry's trajectory: the true steps with errors of a few centimetres and a tenth of a degree.
LidarGraph OdometryWithStepErrors(const std::vector<Eigen::Isometry3d>& truth) {
  std::mt19937 rng(5);
  std::normal_distribution<double> centimetres(0, 0.03), tenth_degree(0, 0.1 * M_PI / 180);
  LidarGraph graph;
  graph.world_from_lidar.push_back(truth[0]);
  for (size_t k = 1; k < truth.size(); ++k) {
    LidarEdge edge;
    edge.target = k - 1;
    edge.source = k;
    edge.odometry = true;
    edge.target_from_source = truth[k - 1].inverse() * truth[k];
    edge.target_from_source.translation() +=
        Eigen::Vector3d(centimetres(rng), centimetres(rng), centimetres(rng));
    edge.target_from_source.linear() =
        Eigen::AngleAxisd(tenth_degree(rng), Eigen::Vector3d::UnitZ()).toRotationMatrix() *
        edge.target_from_source.linear();
    edge.registration.hessian = 1e4 * Eigen::Matrix<double, 6, 6>::Identity();
    edge.registration.rmse = 0.03;
    graph.edges.push_back(edge);
    graph.world_from_lidar.push_back(graph.world_from_lidar.back() * edge.target_from_source);
  }
  graph.component.assign(truth.size(), 0);
  graph.num_components = 1;
  return graph;
}

double WorstStepError(const std::vector<Eigen::Isometry3d>& truth,
                      const std::vector<Eigen::Isometry3d>& poses) {
  double worst_m = 0;
  for (size_t k = 1; k < truth.size(); ++k) {
    const Eigen::Isometry3d true_step = truth[k - 1].inverse() * truth[k];
    const Eigen::Isometry3d step = poses[k - 1].inverse() * poses[k];
    worst_m = std::max(worst_m, (true_step.inverse() * step).translation().norm());
  }
  return worst_m;
}

// ICP between neighbouring sweeps brings an odometry's steps of a few centimetres' error to the
// pairwise path's precision; every step's pair is accepted and replaces the odometry's edge.
TEST(RefineTrajectory, BringsTheStepsToThePairwisePrecision) {
  testing::ScopedTempDir dir("colmap_lidar_refine");
  std::vector<std::string> paths;
  const std::vector<Eigen::Isometry3d> truth = WriteStreetSweeps(dir, &paths);
  LidarGraph graph = OdometryWithStepErrors(truth);
  const double before_m = WorstStepError(truth, graph.world_from_lidar);
  TrajectoryRefinementOptions options;
  const TrajectoryRefinement refinement = RefineTrajectory(paths, options, &graph);
  const double after_m = WorstStepError(truth, graph.world_from_lidar);
  std::cout << "worst step error " << before_m << " m -> " << after_m << " m; "
            << refinement.num_accepted << " of " << refinement.num_pairs << " pairs" << std::endl;
  EXPECT_EQ(refinement.num_pairs, 21u);  // 11 + 10
  for (const LidarEdge& e : graph.refused) {
    std::cout << "refused " << e.target << "-" << e.source << ": " << e.registration.reason
              << std::endl;
  }
  EXPECT_GE(refinement.num_accepted, 19u);  // measured 20: one of two steps did not converge
  for (const LidarEdge& e : graph.edges) EXPECT_FALSE(e.odometry);  // every step measured
  EXPECT_GT(before_m, 0.04);                                        // 0.065 m
  EXPECT_LT(after_m, 0.0015);                                       // 0.0004 m
}

}  // namespace
}  // namespace colmap_lidar
