#include "lidar/util/atomic_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace colmap_lidar {

void WriteAtomically(const std::string& path,
                     const std::function<bool(const std::string& temporary_path)>& write) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path temporary =
      target.parent_path() / ("." + target.stem().string() + ".tmp" + std::to_string(::getpid()) +
                              target.extension().string());
  const auto remove_temporary = [&temporary]() {
    std::error_code ignored;
    fs::remove(temporary, ignored);
  };
  try {
    if (!write(temporary.string())) {
      remove_temporary();
      throw std::runtime_error("Cannot write " + path + " (disk full or no permission?)");
    }
  } catch (...) {
    remove_temporary();
    throw;
  }
  fs::rename(temporary, target);
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  WriteAtomically(path, [&contents](const std::string& temporary) {
    std::ofstream file(temporary, std::ios::binary);
    file << contents;
    file.flush();
    return static_cast<bool>(file);
  });
}

PartialOutputFolder::PartialOutputFolder(const std::string& output_path)
    : output_path_(output_path), partial_path_(output_path + ".partial") {
  std::filesystem::remove_all(partial_path_);
  std::filesystem::create_directories(partial_path_);
}

PartialOutputFolder::~PartialOutputFolder() {
  if (committed_) return;
  std::error_code ignored;
  std::filesystem::remove_all(partial_path_, ignored);
}

std::string PartialOutputFolder::File(const std::string& name) const {
  return (std::filesystem::path(partial_path_) / name).string();
}

void PartialOutputFolder::Commit() {
  std::filesystem::remove_all(output_path_);
  std::filesystem::rename(partial_path_, output_path_);
  committed_ = true;
}

}  // namespace colmap_lidar
