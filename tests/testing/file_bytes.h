// A file's whole content, for tests that compare outputs byte by byte.
#pragma once

#include <fstream>
#include <iterator>
#include <string>

namespace colmap_lidar {
namespace testing {

// The bytes of `path`; empty if it cannot be read.
inline std::string FileBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

}  // namespace testing
}  // namespace colmap_lidar
