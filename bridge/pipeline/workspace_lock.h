// One pipeline per workspace: an exclusive flock(2) on WS/pipeline.lock, which holds the holder's pid.
// The kernel releases the lock when the holder exits or is killed (SIGKILL included), so a stale file
// never blocks a rerun; a second pipeline on a locked workspace is refused with the holder's pid.
#pragma once

#include <string>

namespace colmap_lidar {

class WorkspaceLock {
 public:
  // Throws std::runtime_error naming the lock file and the holder's pid if another process holds it.
  explicit WorkspaceLock(const std::string& workspace_path);
  ~WorkspaceLock();
  WorkspaceLock(const WorkspaceLock&) = delete;
  WorkspaceLock& operator=(const WorkspaceLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace colmap_lidar
