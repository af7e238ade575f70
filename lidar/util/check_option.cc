#include "lidar/util/check_option.h"

#include <iostream>

namespace colmap_lidar {
namespace internal {

void ReportFailedOption(const char* condition, const char* file, int line) {
  std::cerr << "Check failed: " << condition << " (" << file << ":" << line << ")" << std::endl;
}

}  // namespace internal
}  // namespace colmap_lidar
