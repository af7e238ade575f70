// The same output with one thread and with four: import_dataset's matching and verification,
// lidar_registrator, joint_adjuster and densifier on the default pipeline workspace
// (tests/testing/pipeline_fixture.h), each run with OMP_NUM_THREADS=1 and =4 into folders of its own
// and compared byte by byte (report.json without its timings).
#include "tests/testing/file_bytes.h"
#include "tests/testing/pipeline_fixture.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::FileBytes;
using testing::kCli;
using testing::ReadJson;
using testing::RunCommand;

// `json` without the keys that hold wall-clock times.
nlohmann::json WithoutTimings(nlohmann::json json) {
  if (json.is_object()) {
    for (auto it = json.begin(); it != json.end();) {
      const std::string& key = it.key();
      if (key == "seconds" || key.find("_seconds") != std::string::npos) {
        it = json.erase(it);
      } else {
        *it = WithoutTimings(*it);
        ++it;
      }
    }
  } else if (json.is_array()) {
    for (nlohmann::json& item : json) item = WithoutTimings(item);
  }
  return json;
}

class DeterminismTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::is_regular_file(fixture_.File("sparse/joint/cam_from_lidar.txt")))
        << "the pipeline fixture is missing: run PipelineTest.DefaultScene... first (ctest does)";
  }

  // Runs `arguments` of the CLI with `threads` OpenMP threads; the command must succeed.
  static void RunWithThreads(int threads, const std::string& arguments) {
    const auto run =
        RunCommand("OMP_NUM_THREADS=" + std::to_string(threads) + " " + kCli + " " + arguments);
    ASSERT_EQ(run.exit_code, 0) << arguments << "\n" << run.output;
  }

  // Each of `files` (in folders `one` and `four`) holds the same bytes.
  static void ExpectSameFiles(const std::string& one,
                              const std::string& four,
                              const std::vector<std::string>& files) {
    for (const std::string& name : files) {
      const std::string bytes = FileBytes(one + "/" + name);
      EXPECT_FALSE(bytes.empty()) << "cannot read " << one << "/" << name;
      EXPECT_EQ(bytes, FileBytes(four + "/" + name)) << name;
    }
  }

  std::string Output(const std::string& name) const { return fixture_.File("determinism/" + name); }

  const testing::PipelineFixture fixture_;
};

// The fixture's database without its matches, so that import_dataset matches and verifies again
// (its features are kept: extraction is COLMAP's and not in question here).
std::string DatabaseWithoutMatches(const testing::PipelineFixture& f, const std::string& path) {
  fs::create_directories(fs::path(path).parent_path());
  const auto copy = RunCommand("sqlite3 " + f.File("database.db") + " \".backup '" + path + "'\"");
  EXPECT_EQ(copy.exit_code, 0) << copy.output;
  const auto clear =
      RunCommand("sqlite3 " + path + " 'DELETE FROM matches; DELETE FROM two_view_geometries;'");
  EXPECT_EQ(clear.exit_code, 0) << clear.output;
  return path;
}

// Every matched pair's raw matches, and every verified pair's geometry, as text.
std::string MatchTables(const std::string& database) {
  return RunCommand("sqlite3 " + database +
                    " 'SELECT pair_id, rows, hex(data) FROM matches ORDER BY pair_id;"
                    " SELECT pair_id, rows, config, hex(data), hex(F), hex(E), hex(H)"
                    " FROM two_view_geometries ORDER BY pair_id;'")
      .output;
}

TEST_F(DeterminismTest, MatchesAndVerifiedPairsAreTheSameWithOneAndFourThreads) {
  const testing::PipelineFixture& f = fixture_;
  fs::remove_all(Output("import"));
  for (const int threads : {1, 4}) {
    const std::string database =
        DatabaseWithoutMatches(f, Output("import/" + std::to_string(threads) + ".db"));
    RunWithThreads(threads,
                   "import_dataset --dataset_path " + f.dataset + " --database_path " + database +
                       " --SiftMatching.num_threads " + std::to_string(threads));
  }
  const std::string one = MatchTables(Output("import/1.db"));
  EXPECT_GT(one.size(), 1000u);  // the pairs are there
  EXPECT_EQ(one, MatchTables(Output("import/4.db")));
}

TEST_F(DeterminismTest, RegistrationJointAdjustmentAndDenseModelAreTheSameWithOneAndFourThreads) {
  const testing::PipelineFixture& f = fixture_;
  // Only this test's folders: the other test of this file may run at the same time (ctest -j).
  for (const char* folder : {"1", "4"}) fs::remove_all(Output(folder));
  for (const int threads : {1, 4}) {
    const std::string out = Output(std::to_string(threads));
    RunWithThreads(
        threads,
        "lidar_registrator --lidar_path " + f.dataset + "/lidar --output_path " + out + "/lidar");
    RunWithThreads(threads,
                   "joint_adjuster --database_path " + f.File("database.db") + " --input_path " +
                       f.File("sparse/initial") + " --dataset_path " + f.dataset +
                       " --registration_path " + f.File("lidar") + " --output_path " + out +
                       "/joint");
    RunWithThreads(threads,
                   "densifier --input_path " + out + "/joint --dataset_path " + f.dataset +
                       " --depth_path " + f.File("stereo") + " --output_path " + out + "/dense");
  }
  const std::string one = Output("1"), four = Output("4");
  ExpectSameFiles(one + "/lidar", four + "/lidar", {"lidar_poses.txt", "pairs.txt"});
  ExpectSameFiles(one + "/joint",
                  four + "/joint",
                  {"cam_from_lidar.txt", "cameras.bin", "images.bin", "points3D.bin"});
  EXPECT_EQ(WithoutTimings(ReadJson(one + "/joint/report.json")),
            WithoutTimings(ReadJson(four + "/joint/report.json")));
  ExpectSameFiles(one + "/dense", four + "/dense", {"fused.ply", "lidar_map.ply"});
}

}  // namespace
}  // namespace colmap_lidar
