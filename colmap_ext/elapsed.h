// Wall-clock seconds since a start time, for progress lines and reports (one helper for the layers
// above lidar/).
#pragma once

#include <chrono>

namespace colmap_lidar {

inline double SecondsSince(const std::chrono::steady_clock::time_point& start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace colmap_lidar
