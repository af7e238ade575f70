// libFuzzer target: COLMAP depth maps as our densifier reads them (colmap_ext ReadColmapDepthMap: our
// header check, then COLMAP's reader). Errors are std::exception; anything else is a finding.
#include "colmap_ext/dense_workspace.h"
#include "tests/fuzz/fuzz_input_file.h"

#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = colmap_lidar::WriteFuzzInput(data, size, ".geometric.bin");
  if (path.empty()) return 0;
  try {
    colmap_lidar::ReadColmapDepthMap(path);
  } catch (const std::exception&) {
  }
  std::remove(path.c_str());
  return 0;
}
