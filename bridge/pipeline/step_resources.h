// What one pipeline step costs: wall time, CPU time (every thread of the process) and peak resident
// memory. Linux only: getrusage(RUSAGE_SELF) and VmHWM of /proc/self/status, whose high-water mark is
// reset through /proc/self/clear_refs at the start so that each step has its own peak (on a kernel
// older than Linux 4.0, which has no reset, the peak is the process's so far).
#pragma once

#include <chrono>

namespace colmap_lidar {

class StepResources {
 public:
  // Starts measuring: resets the peak, notes the clocks.
  StepResources();

  double WallSeconds() const;
  double CpuSeconds() const;
  double PeakResidentMiB() const;

 private:
  std::chrono::steady_clock::time_point wall_start_;
  double cpu_start_ = 0;
};

}  // namespace colmap_lidar
