// Uses one call of each installed layer: prints "consumer ok" and exits 0 when they work.
//   consumer [FIXTURE]
// With FIXTURE (the pipeline's default workspace, tests/testing/pipeline_fixture.h: FIXTURE/dataset
// and FIXTURE/ws), it also reruns the joint adjuster step through the library on the CLI pipeline's
// initial model and requires the CLI's cam_from_lidar (FIXTURE/ws/sparse/joint) to 1e-9.
#include "bridge/initialization/hand_eye.h"
#include "bridge/initialization/lidar_registration_files.h"
#include "bridge/pipeline/joint_step.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/pose_graph.h"

#include <filesystem>
#include <iostream>

namespace {

using namespace colmap_lidar;

bool LayersWork() {
  // lidar: a two-node pose graph.
  Eigen::Isometry3d a_from_b = Eigen::Isometry3d::Identity();
  a_from_b.translation() = Eigen::Vector3d(1, 2, 3);
  const PoseGraphSolution graph =
      SolvePoseGraph(2, {{0, 1, a_from_b, 1.0, {}}}, PoseGraphOptions());
  // colmap_ext and bridge: COLMAP types through our headers, an options check.
  const colmap::Rigid3d pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 2, 3));
  return graph.world_from_node[1].translation().isApprox(pose.translation) &&
         HandEyeOptions().Check();
}

// The joint step as the pipeline runs it (default options, the registrator's clouds), into a
// temporary folder; true if its cam_from_lidar is the CLI's to 1e-9.
bool JointStepReproducesTheCli(const std::string& fixture) {
  const std::string ws = fixture + "/ws";
  const std::string output =
      (std::filesystem::temp_directory_path() / "colmap_lidar_consumer_joint").string();
  RunJointAdjusterStep(
      WithRegistratorClouds(ReadStationDataset(fixture + "/dataset"), ws + "/lidar"),
      {ws + "/database.db", ws + "/sparse/initial", "", output},
      JointAdjusterStepOptions());
  const colmap::Rigid3d library = ReadPoseFile(output + "/cam_from_lidar.txt");
  const colmap::Rigid3d cli = ReadPoseFile(ws + "/sparse/joint/cam_from_lidar.txt");
  std::filesystem::remove_all(output);
  const double rotation = library.rotation.angularDistance(cli.rotation);
  const double translation = (library.translation - cli.translation).norm();
  std::cout << "joint step through the library vs the CLI: rotation " << rotation
            << " rad, translation " << translation << " m" << std::endl;
  return rotation < 1e-9 && translation < 1e-9;
}

}  // namespace

int main(int argc, char** argv) {
  bool ok = LayersWork();
  if (argc > 1) ok = ok && JointStepReproducesTheCli(argv[1]);
  std::cout << (ok ? "consumer ok" : "consumer FAILED") << std::endl;
  return ok ? 0 : 1;
}
