// The fuzz targets' input as a file: our readers take paths. One file per process, named so that the
// reader sees the expected extension or name; removed by the caller after reading.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace colmap_lidar {

// Writes `data` to /tmp/colmap_lidar_fuzz_<pid><suffix>; returns the path ("" if it cannot be written).
inline std::string WriteFuzzInput(const uint8_t* data, size_t size, const std::string& suffix) {
  const std::string path = "/tmp/colmap_lidar_fuzz_" + std::to_string(getpid()) + suffix;
  FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) return "";
  std::fwrite(data, 1, size, file);
  std::fclose(file);
  return path;
}

}  // namespace colmap_lidar
