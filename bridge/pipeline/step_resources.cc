#include "bridge/pipeline/step_resources.h"

#include <sys/resource.h>

#include <fstream>
#include <sstream>
#include <string>

namespace colmap_lidar {
namespace {

double ProcessCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// "5" resets the peak resident set size (VmHWM) of the process (Linux >= 4.0; ignored before).
void ResetPeakResident() {
  std::ofstream clear_refs("/proc/self/clear_refs");
  clear_refs << "5";
}

}  // namespace

StepResources::StepResources()
    : wall_start_(std::chrono::steady_clock::now()), cpu_start_(ProcessCpuSeconds()) {
  ResetPeakResident();
}

double StepResources::WallSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
}

double StepResources::CpuSeconds() const { return ProcessCpuSeconds() - cpu_start_; }

double StepResources::PeakResidentMiB() const {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) {
      std::istringstream fields(line.substr(6));
      double kib = 0;
      fields >> kib;
      return kib / 1024.0;
    }
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // kilobytes on Linux
}

}  // namespace colmap_lidar
