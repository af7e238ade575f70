#include "lidar/util/atomic_file.h"

#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

std::string Read(const std::string& path) {
  std::ifstream file(path);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

size_t NumEntries(const fs::path& folder) {
  return static_cast<size_t>(std::distance(fs::directory_iterator(folder), {}));
}

TEST(AtomicFile, AFailedWriteKeepsTheOldFileAndLeavesNoTemporary) {
  testing::ScopedTempDir dir;
  WriteFileAtomically(dir.File("a.txt"), "old\n");
  EXPECT_THROW(WriteAtomically(dir.File("a.txt"),
                               [](const std::string& temporary) {
                                 std::ofstream(temporary) << "half";
                                 return false;
                               }),
               std::runtime_error);
  EXPECT_THROW(WriteAtomically(dir.File("a.txt"),
                               [](const std::string& temporary) -> bool {
                                 std::ofstream(temporary) << "half";
                                 throw std::invalid_argument("writer failed");
                               }),
               std::invalid_argument);
  EXPECT_EQ(Read(dir.File("a.txt")), "old\n");
  EXPECT_EQ(NumEntries(dir.Path()), 1u);
  // The temporary keeps the extension (writers such as cv::imwrite choose the format by it).
  std::string seen;
  WriteAtomically(dir.File("b.png"), [&seen](const std::string& temporary) {
    seen = temporary;
    return static_cast<bool>(std::ofstream(temporary) << "png");
  });
  EXPECT_EQ(fs::path(seen).extension(), ".png");
  EXPECT_EQ(fs::path(seen).parent_path(), dir.Path());
}

TEST(AtomicFile, PartialFolderReplacesTheOutputOnlyWhenCommitted) {
  testing::ScopedTempDir dir;
  const std::string output = dir.File("out");
  fs::create_directories(output);
  WriteFileAtomically(output + "/old.txt", "old");
  try {
    PartialOutputFolder partial(output);
    WriteFileAtomically(partial.File("new.txt"), "new");
    throw std::runtime_error("step failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(fs::exists(output + ".partial"));
  EXPECT_TRUE(fs::exists(output + "/old.txt"));
  {
    PartialOutputFolder partial(output);
    WriteFileAtomically(partial.File("new.txt"), "new");
    EXPECT_FALSE(fs::exists(output + "/new.txt"));
    partial.Commit();
  }
  EXPECT_EQ(Read(output + "/new.txt"), "new");
  EXPECT_FALSE(fs::exists(output + "/old.txt"));
  EXPECT_FALSE(fs::exists(output + ".partial"));
}

}  // namespace
}  // namespace colmap_lidar
