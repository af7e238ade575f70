// The bad-input matrix (docs/reliability.md): each case breaks one input of a small simulated dataset
// the way a user's capture breaks, runs the real CLI on it and checks what the user gets: a non-zero
// exit without a signal, exactly one "ERROR:" line naming the file (and the key or line where it
// applies), no output left behind, and every input file byte-for-byte unchanged.
#include "bridge/simulation/simulate_dataset.h"
#include "lidar/cloud_io.h"
#include "tests/testing/run_command.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sqlite3.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;
const std::string kCli = COLMAP_LIDAR_CLI_EXE;

struct BadInputCase {
  std::string name;
  // Breaks the copy of the dataset at `dataset` (ROOT/dataset; other input files go into ROOT).
  std::function<void(const fs::path& dataset)> mutate;
  // The CLI's arguments; {dataset}, {root} and {out} (= ROOT/out) are replaced.
  std::string arguments;
  // What the ERROR line must contain (the file, the key, the cause).
  std::vector<std::string> needles;
  // ROOT/full is a 64 KiB tmpfs (a full disk); skipped with a message where it cannot be mounted.
  bool full_disk = false;
};

// Test names instead of byte dumps in GoogleTest's messages.
void PrintTo(const BadInputCase& c, std::ostream* os) { *os << c.name; }

std::string ReadBytes(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << file.rdbuf();
  return bytes.str();
}

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// Every file under `root` but outside `out` with its bytes.
std::map<std::string, std::string> Snapshot(const fs::path& root, const fs::path& out) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const std::string path = entry.path().string();
    if (entry.is_regular_file() && path.rfind(out.string(), 0) != 0) {
      files[path] = ReadBytes(entry.path());
    }
  }
  return files;
}

// rig.json changed by `edit`.
std::function<void(const fs::path&)> EditRig(std::function<void(nlohmann::json*)> edit) {
  return [=](const fs::path& dataset) {
    nlohmann::json rig = nlohmann::json::parse(ReadBytes(dataset / "rig.json"));
    edit(&rig);
    WriteBytes(dataset / "rig.json", rig.dump(2));
  };
}

std::vector<std::string> ErrorLines(const std::string& output) {
  std::vector<std::string> lines;
  std::istringstream stream(output);
  std::string line;
  while (std::getline(stream, line)) {
    if (line.rfind("ERROR:", 0) == 0) lines.push_back(line);
  }
  return lines;
}

class BadInputTest : public ::testing::TestWithParam<BadInputCase> {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::ScopedTempDir("colmap_lidar_bad_input");
    sim::SimulateSmallDataset(dir_->File("dataset"), 3, 0.25, 20000);
  }
  static void TearDownTestSuite() { delete dir_; }
  static testing::ScopedTempDir* dir_;
};
testing::ScopedTempDir* BadInputTest::dir_ = nullptr;

std::string Expand(std::string arguments, const fs::path& root) {
  for (const auto& [key, value] :
       std::vector<std::pair<std::string, std::string>>{{"{dataset}", (root / "dataset").string()},
                                                        {"{root}", root.string()},
                                                        {"{out}", (root / "out").string()}}) {
    for (size_t at; (at = arguments.find(key)) != std::string::npos;) {
      arguments.replace(at, key.size(), value);
    }
  }
  return arguments;
}

TEST_P(BadInputTest, OneClearErrorNoOutputInputsUnchanged) {
  const BadInputCase& c = GetParam();
  const fs::path root = dir_->Path() / c.name;
  fs::remove_all(root);
  fs::create_directories(root);
  fs::copy(dir_->Path() / "dataset", root / "dataset", fs::copy_options::recursive);
  c.mutate(root / "dataset");
  if (c.full_disk) {
    fs::create_directories(root / "full");
    if (RunCommand("mount -t tmpfs -o size=64k tmpfs " + (root / "full").string()).exit_code != 0) {
      GTEST_SKIP()
          << "cannot mount a 64 KiB tmpfs here (needs root): the full-disk case is skipped";
    }
  }
  const fs::path out = root / "out";
  const std::map<std::string, std::string> before = Snapshot(root, out);
  const testing::CommandResult result = RunCommand(kCli + " " + Expand(c.arguments, root));
  if (c.full_disk) RunCommand("umount " + (root / "full").string());
  EXPECT_NE(result.exit_code, -1) << "killed by a signal:\n" << result.output;
  EXPECT_NE(result.exit_code, 0) << result.output;
  const std::vector<std::string> errors = ErrorLines(result.output);
  ASSERT_EQ(errors.size(), 1u) << result.output;
  for (const std::string& needle : c.needles) {
    EXPECT_NE(errors[0].find(needle), std::string::npos) << "'" << needle << "' in " << errors[0];
  }
  EXPECT_FALSE(fs::exists(out)) << "output left behind: " << out;
  EXPECT_TRUE(Snapshot(root, out) == before) << "an input file changed";
}

void CutCloud(const fs::path& dataset, const std::string& file, size_t bytes) {
  const fs::path path = dataset / "lidar" / file;
  fs::resize_file(path, fs::file_size(path) - bytes);
}

// lidar/FILE rewritten as an ASCII PCD with a per-point time field: the cloud's own points, the
// i-th timed by `time(i, n)`.
std::function<void(const fs::path&)> TimeCloud(const std::string& file,
                                               std::function<double(size_t, size_t)> time) {
  return [=](const fs::path& d) {
    const PointCloud cloud = ReadPointCloud((d / "lidar" / file).string());
    std::ostringstream pcd;
    pcd << "VERSION 0.7\nFIELDS x y z t\nSIZE 4 4 4 8\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH "
        << cloud.Size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << cloud.Size()
        << "\nDATA ascii\n";
    for (size_t i = 0; i < cloud.Size(); ++i) {
      const Eigen::Vector3d& p = cloud.points[i];
      pcd << p.x() << " " << p.y() << " " << p.z() << " " << time(i, cloud.Size()) << "\n";
    }
    WriteBytes(d / "lidar" / file, pcd.str());
  };
}

// The sweeps of a moving platform (LiDAR odometry): the third frame is the first one de-skewed,
// by its per-point times.
std::vector<BadInputCase> OdometryCases() {
  const std::string odometry =
      "lidar_registrator --lidar_path {dataset}/lidar --output_path {out} --method odometry "
      "--deskew_sweeps 1";
  return {
      {"odometry_nan_sweep",
       [](const fs::path& d) {
         PointCloud cloud;
         cloud.points.assign(100, Eigen::Vector3d::Constant(std::nan("")));
         WritePointCloud((d / "lidar/001.pcd").string(), cloud);
       },
       odometry,
       {"001.pcd", "NaN"}},
      {"odometry_sweep_out_of_range",
       [](const fs::path& d) {
         PointCloud cloud;
         cloud.points.assign(100, Eigen::Vector3d(0.5, 0, 0));
         WritePointCloud((d / "lidar/001.pcd").string(), cloud);
       },
       odometry,
       {"001.pcd", "range"}},
      {"odometry_sweep_times_all_equal",
       TimeCloud("002.pcd", [](size_t, size_t) { return 7.0; }),
       odometry,
       {"002.pcd", "all equal"}},
      {"odometry_sweep_times_out_of_range",
       TimeCloud("002.pcd", [](size_t i, size_t n) { return i % 200 == 0 ? 1000.0 : 0.1 * i / n; }),
       odometry,
       {"002.pcd", "out of range"}},
      {"odometry_sweep_nan_time",
       TimeCloud("002.pcd", [](size_t i, size_t n) { return i == 7 ? std::nan("") : 0.1 * i / n; }),
       odometry,
       {"002.pcd", "time"}},
  };
}

// The simulator's clouds are lidar/000.pcd ...; the images images/{left,right}/000.png ...
std::vector<BadInputCase> Cases() {
  const std::string registrator =
      "lidar_registrator --lidar_path {dataset}/lidar --output_path {out}";
  const std::string import = "import_dataset --dataset_path {dataset} --database_path {out}";
  return {
      {"empty_pcd",
       [](const fs::path& d) { WriteBytes(d / "lidar/001.pcd", ""); },
       registrator,
       {"001.pcd", "empty"}},
      {"truncated_pcd",
       [](const fs::path& d) { CutCloud(d, "001.pcd", 1000); },
       registrator,
       {"001.pcd", "truncated"}},
      {"random_bytes_pcd",
       [](const fs::path& d) {
         std::string bytes(1000, '\0');
         for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>((i * 7919) % 251);
         WriteBytes(d / "lidar/001.pcd", bytes);
       },
       registrator,
       {"001.pcd", "PCD"}},
      {"nan_cloud",
       [](const fs::path& d) {
         PointCloud cloud;
         cloud.points.assign(100, Eigen::Vector3d::Constant(std::nan("")));
         WritePointCloud((d / "lidar/001.pcd").string(), cloud);
       },
       registrator,
       {"001.pcd", "NaN"}},
      {"truncated_ply",
       [](const fs::path& d) {
         const PointCloud cloud = ReadPointCloud((d / "lidar/001.pcd").string());
         fs::remove(d / "lidar/001.pcd");
         WritePointCloud((d / "lidar/001.ply").string(), cloud);
         CutCloud(d, "001.ply", 1000);
       },
       registrator,
       {"001.ply", "truncated"}},
      {"truncated_kitti_bin",
       [](const fs::path& d) {
         fs::remove(d / "lidar/001.pcd");
         WriteBytes(d / "lidar/001.bin", std::string(100, '\1'));
       },
       registrator,
       {"001.bin", "multiple of 16"}},
      {"cloud_in_millimetres",
       [](const fs::path& d) {
         PointCloud cloud = ReadPointCloud((d / "lidar/001.pcd").string());
         for (Eigen::Vector3d& p : cloud.points) p *= 1000;
         WritePointCloud((d / "lidar/001.pcd").string(), cloud);
       },
       registrator,
       {"001.pcd", "millimetres"}},
      {"duplicated_station",
       [](const fs::path& d) {
         WritePointCloud((d / "lidar/001.ply").string(),
                         ReadPointCloud((d / "lidar/001.pcd").string()));
       },
       registrator,
       {"001", "two clouds"}},
      {"duplicated_station_in_dataset",
       [](const fs::path& d) {
         WritePointCloud((d / "lidar/001.ply").string(),
                         ReadPointCloud((d / "lidar/001.pcd").string()));
       },
       import,
       {"001", "second cloud"}},
      {"rig_not_json",
       [](const fs::path& d) {
         fs::resize_file(d / "rig.json", fs::file_size(d / "rig.json") / 2);
       },
       import,
       {"rig.json"}},
      {"rig_wrong_type",
       EditRig([](nlohmann::json* rig) { (*rig)["left"]["width"] = "wide"; }),
       import,
       {"rig.json", "width"}},
      {"rig_non_unit_quaternion",
       EditRig([](nlohmann::json* rig) {
         (*rig)["right_from_left"]["rotation"] = {2.0, 0.0, 0.0, 0.0};
       }),
       import,
       {"rig.json", "rotation"}},
      {"rig_nan_focal_length",
       EditRig([](nlohmann::json* rig) { (*rig)["left"]["params"][0] = "nan"; }),
       import,
       {"rig.json", "params"}},
      {"cloud_without_image",
       [](const fs::path& d) { fs::remove(d / "images/left/001.png"); },
       import,
       {"001.pcd", "without a left image"}},
      {"image_without_cloud",
       [](const fs::path& d) { fs::remove(d / "lidar/001.pcd"); },
       import,
       {"001"}},
      {"image_of_another_size",
       [](const fs::path& d) {
         cv::imwrite((d / "images/left/001.png").string(),
                     cv::Mat(30, 40, CV_8UC1, cv::Scalar(128)));
       },
       import,
       {"001.png", "40"}},
      {"missing_rig", [](const fs::path& d) { fs::remove(d / "rig.json"); }, import, {"rig.json"}},
      {"database_from_another_program",
       [](const fs::path& d) {
         testing::RunStep("sqlite3 " + (d.parent_path() / "other.db").string() +
                          " 'CREATE TABLE notes (text TEXT); INSERT INTO notes VALUES (1);'");
       },
       "import_dataset --dataset_path {dataset} --database_path {root}/other.db",
       {"other.db", "Not a COLMAP database"}},
      {"full_disk",
       [](const fs::path&) {},
       "import_dataset --dataset_path {dataset} --database_path {root}/full/db.db",
       {"full/db.db", "free on its disk"},
       true},
      {"pipeline_stop_after_unknown_step",
       [](const fs::path&) {},
       "pipeline --dataset_path {dataset} --workspace_path {out} --stop_after densify",
       {"--stop_after densify", "pose_initializer"}},
      {"existing_output_without_overwrite",
       [](const fs::path&) {},
       "simulate_dataset --num_stations 2 --output_path {dataset}",
       {"dataset", "--overwrite"}},
      {"output_below_a_file",
       [](const fs::path& d) { WriteBytes(d.parent_path() / "file", "x"); },
       "lidar_registrator --lidar_path {dataset}/lidar --output_path {root}/file/out",
       {"file/out"}},
      {"deskew_without_sweeps",
       [](const fs::path&) {},
       "deskew_sweeps --dataset_path {dataset} --input_path {root}/model --output_path {out}",
       {"rig.json", "lidar.sweep"}},
      {"missing_lidar_folder",
       [](const fs::path& d) { fs::remove_all(d / "lidar"); },
       registrator,
       {"lidar"}},
  };
}

// Two pipelines on one workspace: the second is refused with the holder's pid and touches nothing;
// once the first has ended (its lock released by the kernel), the workspace is free again.
TEST(WorkspaceLockTest, ASecondPipelineOnTheWorkspaceIsRefused) {
  testing::ScopedTempDir dir("colmap_lidar_lock");
  sim::SimulateSmallDataset(dir.File("dataset"), 3, 0.25, 20000);
  const std::string pipeline = kCli + " pipeline --dataset_path " + dir.File("dataset") +
                               " --workspace_path " + dir.File("ws");
  ASSERT_EQ(std::system((pipeline + " > " + dir.File("first.log") + " 2>&1 &").c_str()), 0);
  const fs::path lock = dir.Path() / "ws" / "pipeline.lock";
  for (int i = 0; i < 300 && (!fs::exists(lock) || fs::file_size(lock) == 0); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(fs::exists(lock));
  const testing::CommandResult second = RunCommand(pipeline);
  EXPECT_EQ(second.exit_code, 1) << second.output;
  const std::vector<std::string> errors = ErrorLines(second.output);
  ASSERT_EQ(errors.size(), 1u) << second.output;
  EXPECT_NE(errors[0].find("in use by another pipeline (pid "), std::string::npos) << errors[0];
  // After the first ends, a rerun gets the workspace (finished steps are skipped).
  testing::CommandResult rerun;
  for (int i = 0; i < 300; ++i) {
    rerun = RunCommand(pipeline);
    if (rerun.output.find("in use by another pipeline") == std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  EXPECT_EQ(rerun.output.find("in use by another pipeline"), std::string::npos) << rerun.output;
}

// An exclusive transaction held by this test process on its own SQLite connection: the command
// under test runs as another process and meets the lock as it would meet another program's.
class ExclusiveTransaction {
 public:
  explicit ExclusiveTransaction(const std::string& database) {
    if (sqlite3_open_v2(database.c_str(), &connection_, SQLITE_OPEN_READWRITE, nullptr) ==
        SQLITE_OK) {
      held_ = sqlite3_exec(connection_, "BEGIN EXCLUSIVE;", nullptr, nullptr, nullptr) == SQLITE_OK;
    }
  }
  ~ExclusiveTransaction() {
    if (held_) sqlite3_exec(connection_, "ROLLBACK;", nullptr, nullptr, nullptr);
    sqlite3_close(connection_);
  }
  bool held() const { return held_; }

 private:
  sqlite3* connection_ = nullptr;
  bool held_ = false;
};

// A database that another program is writing to (an exclusive transaction held open):
// import_dataset waits 5 s for the lock, then gives one error naming the database; the database
// keeps its bytes and no partial copy is left beside it.
TEST(LockedDatabaseTest, ImportIntoADatabaseAnotherProgramWritesIsRefused) {
  testing::ScopedTempDir dir("colmap_lidar_locked_database");
  sim::SimulateSmallDataset(dir.File("dataset"), 3, 0.25, 20000);
  const std::string database = dir.File("database.db");
  const std::string import = kCli + " import_dataset --dataset_path " + dir.File("dataset") +
                             " --database_path " + database;
  const testing::CommandResult first = RunCommand(import);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const std::string before = ReadBytes(database);
  auto lock = std::make_unique<ExclusiveTransaction>(database);
  ASSERT_TRUE(lock->held()) << "could not begin an exclusive transaction on " << database;
  const testing::CommandResult result = RunCommand(import);
  EXPECT_NE(result.exit_code, -1) << "killed by a signal:\n" << result.output;
  EXPECT_NE(result.exit_code, 0) << result.output;
  const std::vector<std::string> errors = ErrorLines(result.output);
  ASSERT_EQ(errors.size(), 1u) << result.output;
  EXPECT_NE(errors[0].find(database), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("locked"), std::string::npos) << errors[0];
  lock.reset();
  EXPECT_EQ(ReadBytes(database), before) << "the locked database changed";
  for (const auto& entry : fs::directory_iterator(dir.Path())) {
    EXPECT_EQ(entry.path().filename().string().find("partial"), std::string::npos)
        << "left behind: " << entry.path();
  }
}

// A read-only output folder. Root writes anywhere, so as root the command runs as `nobody`
// (util-linux's setpriv) on a dataset it may read, below a folder it may not write.
TEST(ReadOnlyOutputTest, AnOutputBelowAReadOnlyFolderIsOneClearError) {
  testing::ScopedTempDir dir("colmap_lidar_read_only");
  std::string as_user;
  if (geteuid() == 0) {
    if (RunCommand("command -v setpriv").exit_code != 0) {
      GTEST_SKIP() << "running as root without setpriv: the read-only case is skipped";
    }
    as_user = "setpriv --reuid=nobody --regid=nogroup --clear-groups ";
  }
  fs::permissions(dir.Path(),
                  fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                      fs::perms::others_read | fs::perms::others_exec);
  sim::SimulateSmallDataset(dir.File("dataset"), 3, 0.25, 20000);
  const fs::path read_only = dir.Path() / "read_only";
  fs::create_directories(read_only);
  fs::permissions(read_only,
                  fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                      fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const testing::CommandResult result =
      RunCommand(as_user + kCli + " lidar_registrator --lidar_path " + dir.File("dataset/lidar") +
                 " --output_path " + (read_only / "out").string());
  EXPECT_NE(result.exit_code, -1) << "killed by a signal:\n" << result.output;
  EXPECT_NE(result.exit_code, 0) << result.output;
  const std::vector<std::string> errors = ErrorLines(result.output);
  ASSERT_EQ(errors.size(), 1u) << result.output;
  EXPECT_NE(errors[0].find("read_only/out"), std::string::npos) << errors[0];
  EXPECT_TRUE(fs::is_empty(read_only)) << "output left in " << read_only;
}

std::string CaseName(const ::testing::TestParamInfo<BadInputCase>& info) { return info.param.name; }

INSTANTIATE_TEST_SUITE_P(Matrix, BadInputTest, ::testing::ValuesIn(Cases()), CaseName);
INSTANTIATE_TEST_SUITE_P(Odometry, BadInputTest, ::testing::ValuesIn(OdometryCases()), CaseName);

}  // namespace
}  // namespace colmap_lidar
