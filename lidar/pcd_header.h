// The header of a PCD file, parsed and checked by us before any byte of the file reaches PCL.
//
// PCL's PCDReader trusts what it reads: a file of random bytes makes it dereference null, and a header
// that claims 10^12 points makes it allocate them. ReadPcdHeader() accepts only a header PCL can act
// on safely: known keywords, FIELDS/SIZE/TYPE/COUNT of one length with valid sizes and types,
// WIDTH x HEIGHT = POINTS, a DATA kind PCL knows, and a data section large enough for the points it
// claims (binary: the exact bytes; binary_compressed: the stored sizes; ascii: two bytes per value).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace colmap_lidar {

struct PcdField {
  std::string name;
  int size = 0;   // bytes of one value: 1, 2, 4 or 8
  char type = 0;  // 'F' float, 'I' signed, 'U' unsigned
  int count = 1;  // values per point
};

struct PcdHeader {
  std::vector<PcdField> fields;
  uint64_t width = 0;
  uint64_t height = 1;
  uint64_t num_points = 0;
  std::string data;          // ascii | binary | binary_compressed
  uint64_t data_offset = 0;  // bytes from the start of the file to the data section
  uint64_t point_step = 0;   // bytes of one point in the binary encodings
};

// Reads and checks the header of `path`; throws std::runtime_error "Cannot read point cloud PATH:
// <problem>" naming the header line where it applies.
PcdHeader ReadPcdHeader(const std::string& path);

}  // namespace colmap_lidar
