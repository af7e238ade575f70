#include "bridge/pipeline/workspace_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace colmap_lidar {

WorkspaceLock::WorkspaceLock(const std::string& workspace_path) {
  std::filesystem::create_directories(workspace_path);
  const std::string path = (std::filesystem::path(workspace_path) / "pipeline.lock").string();
  fd_ = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw std::runtime_error("cannot open the workspace lock " + path + ": " +
                             std::strerror(errno));
  }
  if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    char holder[32] = {0};
    const ssize_t n = pread(fd_, holder, sizeof(holder) - 1, 0);
    close(fd_);
    fd_ = -1;
    throw std::runtime_error("the workspace " + workspace_path +
                             " is in use by another pipeline (pid " +
                             std::string(holder, n > 0 ? static_cast<size_t>(n) : 0) + ", " + path +
                             "); wait for it to finish or stop it");
  }
  const std::string pid = std::to_string(getpid());
  if (ftruncate(fd_, 0) != 0 || pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
    // The lock is held either way; the pid only makes the message of a second pipeline clearer.
  }
}

WorkspaceLock::~WorkspaceLock() {
  if (fd_ >= 0) close(fd_);  // releases the flock
}

}  // namespace colmap_lidar
