// Kill it, run it again (docs/reliability.md): the pipeline is killed with SIGKILL at 10 seeded moments
// spread over an uninterrupted run's duration (every step gets hit). After each kill the database passes
// SQLite's integrity check, no step is marked done without its output, no OUTPUT.partial folder stands
// where a result belongs, and a rerun on the same workspace finishes and gives the uninterrupted run's
// cam_from_lidar within the run-to-run spread of COLMAP's feature matching (our own steps are
// deterministic; docs/reliability.md).
#include "colmap_ext/station_dataset.h"
#include "tests/simulator/simulate_dataset.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <random>
#include <string>
#include <thread>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;
const std::string kCli = COLMAP_LIDAR_CLI_EXE;
// The dataset's 60 k rays per station keep the test quick, but at that density the registrator
// accepts only degenerate edges between most stations (wrong by 70-145 deg), which the pose
// initializer leaves out by default: the pipeline would then stop with too few stations. This test is
// about restarting, not accuracy, so it keeps them.
const std::string kPipeline = kCli + " pipeline --PoseInitializer.use_degenerate_lidar_edges 1";

// Starts `pipeline` on DATASET into WS with its output in LOG; returns the child's pid.
pid_t StartPipeline(const std::string& dataset, const std::string& ws, const std::string& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string command = "exec " + kPipeline + " --dataset_path " + dataset +
                                " --workspace_path " + ws + " > " + log + " 2>&1";
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

double AngleDeg(const colmap::Rigid3d& a, const colmap::Rigid3d& b) {
  return a.rotation.angularDistance(b.rotation) * 180 / M_PI;
}

// What a killed workspace must satisfy before the rerun.
void ExpectConsistentWorkspace(const fs::path& ws, const std::string& when) {
  if (fs::exists(ws / "database.db")) {
    const testing::CommandResult check =
        RunCommand("sqlite3 " + (ws / "database.db").string() + " 'PRAGMA integrity_check;'");
    EXPECT_EQ(check.output, "ok\n") << when;
  }
  const std::vector<std::pair<std::string, fs::path>> outputs = {
      {"import_dataset", ws / "database.db"},
      {"lidar_registrator", ws / "lidar" / "pairs.txt"},
      {"pose_initializer", ws / "sparse" / "initial" / "cam_from_lidar.txt"},
      {"joint_adjuster", ws / "sparse" / "joint" / "cam_from_lidar.txt"},
      {"densifier", ws / "dense" / "fused.ply"}};
  for (const auto& [step, output] : outputs) {
    if (fs::exists(ws / "steps" / (step + ".done"))) {
      EXPECT_TRUE(fs::exists(output))
          << when << ": " << step << " is marked done without " << output;
    }
  }
  for (const fs::path& result :
       {ws / "sparse" / "initial", ws / "sparse" / "joint", ws / "dense"}) {
    EXPECT_FALSE(fs::exists(result) && !fs::exists(result / "cameras.bin") &&
                 !fs::exists(result / "fused.ply"))
        << when << ": " << result << " exists but is not complete";
  }
}

TEST(KillRerunTest, KilledAtTenMomentsTheRerunGivesTheSameCalibration) {
  testing::ScopedTempDir dir("colmap_lidar_kill");
  sim::SimulateSmallDataset(dir.File("dataset"), 6, 0.5, 60000);

  const auto start = std::chrono::steady_clock::now();
  const pid_t reference =
      StartPipeline(dir.File("dataset"), dir.File("reference"), dir.File("r.log"));
  int status = 0;
  ASSERT_EQ(waitpid(reference, &status, 0), reference);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "see " << dir.File("r.log");
  const double duration_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const colmap::Rigid3d expected =
      ReadPoseFile(dir.File("reference/sparse/joint/cam_from_lidar.txt"));

  std::mt19937 rng(17);
  for (int k = 0; k < 10; ++k) {
    // Moments spread over the whole run: the k-th tenth of it, at a seeded place within.
    const double at_s = duration_s * (k + std::uniform_real_distribution<double>(0, 1)(rng)) / 10;
    const fs::path ws = dir.Path() / ("ws" + std::to_string(k));
    const pid_t pid = StartPipeline(dir.File("dataset"), ws.string(), dir.File("killed.log"));
    std::this_thread::sleep_for(std::chrono::duration<double>(at_s));
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    const std::string when = "killed at " + std::to_string(at_s) + " s";
    ExpectConsistentWorkspace(ws, when);
    const testing::CommandResult rerun = RunCommand(
        kPipeline + " --dataset_path " + dir.File("dataset") + " --workspace_path " + ws.string());
    ASSERT_EQ(rerun.exit_code, 0) << when << "\n" << rerun.output;
    const colmap::Rigid3d result = ReadPoseFile((ws / "sparse/joint/cam_from_lidar.txt").string());
    // COLMAP's matching differs from run to run (docs/reliability.md, Determinism): measured between
    // the uninterrupted run and 10 reruns up to 0.107 deg, 4.8 mm; bounds about 3x.
    const double rotation_deg = AngleDeg(result, expected);
    const double translation_mm = 1000 * (result.translation - expected.translation).norm();
    std::cout << when << ": rerun differs from the uninterrupted run by " << rotation_deg
              << " deg, " << translation_mm << " mm" << std::endl;
    EXPECT_LT(rotation_deg, 0.3) << when;
    EXPECT_LT(translation_mm, 15) << when;
    EXPECT_TRUE(fs::exists(ws / "dense" / "fused.ply")) << when;
    fs::remove_all(ws);
  }
}

}  // namespace
}  // namespace colmap_lidar
