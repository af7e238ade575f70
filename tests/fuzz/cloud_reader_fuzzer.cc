// libFuzzer target: one of our point-cloud readers (lidar/cloud_io.h) on arbitrary bytes. The readers
// take a path, so the input is written to a file with the target's extension (FUZZ_EXTENSION: .pcd,
// .ply, .bin or .xyz). A reader may throw (the CLI turns any std::exception into the user's "ERROR:"
// line); anything else (a crash, a sanitizer report, a hang, an allocation above libFuzzer's
// -malloc_limit_mb) is a finding.
#include "lidar/cloud_io.h"
#include "tests/fuzz/fuzz_input_file.h"

#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = colmap_lidar::WriteFuzzInput(data, size, FUZZ_EXTENSION);
  if (path.empty()) return 0;
  try {
    colmap_lidar::ReadStationCloud(path);
  } catch (const std::exception&) {
  }
  std::remove(path.c_str());
  return 0;
}
