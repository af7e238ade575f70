// libFuzzer target: COLMAP depth maps as our densifier reads them (colmap_ext ReadColmapDepthMap: our
// header check, then COLMAP's reader). Errors are std::exception; anything else is a finding.
#include "colmap_ext/dense_workspace.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path =
      "/tmp/colmap_lidar_fuzz_" + std::to_string(getpid()) + ".geometric.bin";
  FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) return 0;
  std::fwrite(data, 1, size, file);
  std::fclose(file);
  try {
    colmap_lidar::ReadColmapDepthMap(path);
  } catch (const std::exception&) {
  }
  std::remove(path.c_str());
  return 0;
}
