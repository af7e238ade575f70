// evaluate_trajectory through the CLI on the simulator's drive (sim::MakeStations, the street, 40
// frames): the true camera trajectory with an injected 1 % scale error and a yaw drift of
// 0.01 deg/m must read back as such; bad inputs give one clear error and no output.
#include "bridge/simulation/scene.h"
#include "bridge/simulation/sensor_pod.h"
#include "colmap_ext/station_dataset.h"
#include "tests/testing/distorted_trajectory.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;

const std::string kCli = COLMAP_LIDAR_CLI_EXE;

std::map<std::string, colmap::Rigid3d> NamedDrive(const std::vector<colmap::Rigid3d>& poses) {
  std::map<std::string, colmap::Rigid3d> named;
  char name[16];
  for (size_t k = 0; k < poses.size(); ++k) {
    std::snprintf(name, sizeof(name), "%03zu", k);
    named[name] = poses[k];
  }
  return named;
}

// The drive with each step's translation scaled by 1.01 and a turn of 0.01 deg per metre about the
// camera's vertical (its y axis), as cam_from_world poses.
std::vector<colmap::Rigid3d> Distorted(const std::vector<colmap::Rigid3d>& cam_from_world) {
  std::vector<colmap::Rigid3d> world_from_cam;
  for (const colmap::Rigid3d& pose : cam_from_world)
    world_from_cam.push_back(colmap::Inverse(pose));
  std::vector<colmap::Rigid3d> distorted;
  for (const colmap::Rigid3d& pose :
       testing::DistortedTrajectory(world_from_cam, 1.01, 0.01, Eigen::Vector3d::UnitY())) {
    distorted.push_back(colmap::Inverse(pose));
  }
  return distorted;
}

TEST(EvaluateTrajectoryTest, AnInjectedScaleErrorAndYawDriftReadBack) {
  testing::ScopedTempDir dir("colmap_lidar_evaluate_trajectory");
  const sim::Scene scene = sim::Scene::Create("street");
  const std::vector<colmap::Rigid3d> truth = sim::MakeStations(scene, 40, sim::Motion::kDrive, 1);
  WriteNamedPoses(dir.File("cam_from_world.txt"), "truth", NamedDrive(truth));
  WriteNamedPoses(dir.File("estimate_from_world.txt"), "distorted", NamedDrive(Distorted(truth)));
  const auto run = RunCommand(kCli + " evaluate_trajectory --trajectory_path " +
                              dir.File("estimate_from_world.txt") + " --reference_path " +
                              dir.File("cam_from_world.txt") +
                              " --lengths_m 5,10,20 --output_path " + dir.File("evaluation"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream file(dir.File("evaluation/metrics.json"));
  const nlohmann::json metrics = nlohmann::json::parse(file);
  const nlohmann::json& relative = metrics["relative"];
  std::cout << run.output;
  // Steps of 0.5-1 m: a segment's first frame at or past L adds at most one step to L.
  EXPECT_NEAR(relative["translation_percent"].get<double>(), 1.0, 0.1);
  EXPECT_GE(relative["rotation_deg_per_m"].get<double>(), 0.01 - 1e-9);
  EXPECT_LE(relative["rotation_deg_per_m"].get<double>(), 0.01 * (1 + 1.0 / 5));
  EXPECT_EQ(metrics["steps"].size(), 39u);
}

TEST(EvaluateTrajectoryTest, BadInputGivesOneClearErrorAndNoOutput) {
  testing::ScopedTempDir dir("colmap_lidar_evaluate_trajectory");
  std::ofstream(dir.File("poses.txt")) << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 nan 0 1 0 0 0 0 1 0\n";
  const auto run = RunCommand(kCli + " evaluate_trajectory --trajectory_path " +
                              dir.File("poses.txt") + " --reference_path " + dir.File("poses.txt") +
                              " --output_path " + dir.File("out"));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find(dir.File("poses.txt") + ":2: 'nan' is not a finite number"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(fs::exists(dir.File("out")));
  const auto missing = RunCommand(kCli + " evaluate_trajectory --trajectory_path " +
                                  dir.File("none.txt") + " --reference_path " +
                                  dir.File("poses.txt") + " --output_path " + dir.File("out"));
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("none.txt: no such trajectory file"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir.File("out")));
}

}  // namespace
}  // namespace colmap_lidar
