#include "lidar/atomic_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace colmap_lidar {

void WriteLidarFileAtomically(const std::string& path,
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

}  // namespace colmap_lidar
