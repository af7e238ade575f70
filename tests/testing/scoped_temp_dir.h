// A temporary directory that is removed when the object goes out of scope (tests only).
#pragma once

#include <filesystem>
#include <random>
#include <string>

namespace colmap_lidar {
namespace testing {

class ScopedTempDir {
 public:
  explicit ScopedTempDir(const std::string& prefix = "colmap_lidar_test")
      : path_(std::filesystem::temp_directory_path() /
              (prefix + "_" + std::to_string(std::random_device()()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScopedTempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;

  const std::filesystem::path& Path() const { return path_; }
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace testing
}  // namespace colmap_lidar
