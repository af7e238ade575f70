#include "lidar/pcd_header.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

// A header longer than this is not a PCD header (PCL's own files have ~250 bytes).
constexpr uint64_t kMaxHeaderBytes = 1 << 16;
// LZF cannot expand data by more than about 1:100 (a 3-byte back-reference copies at most 264
// bytes); a binary_compressed header that claims more is refused before anything is allocated.
constexpr uint64_t kMaxLzfExpansion = 128;

[[noreturn]] void Fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error("Cannot read point cloud " + path + ": " + problem);
}

// line 0: the problem spans several lines.
[[noreturn]] void FailAt(const std::string& path, int line, const std::string& problem) {
  Fail(path,
       (line > 0 ? "PCD header line " + std::to_string(line) : "PCD header") + ": " + problem);
}

uint64_t ParseCount(const std::string& path, int line, const std::string& token) {
  if (token.empty() || token.find_first_not_of("0123456789") != std::string::npos ||
      token.size() > 15) {
    FailAt(path, line, "'" + token + "' is not a count");
  }
  return std::stoull(token);
}

// The line of `text` that starts at *begin (without its '\n'); *begin moves past it.
std::string NextLine(const std::string& text, size_t* begin) {
  size_t end = text.find('\n', *begin);
  if (end == std::string::npos) end = text.size();
  std::string line = text.substr(*begin, end - *begin);
  *begin = end + 1;
  return line;
}

std::vector<std::string> Tokens(std::istringstream& line) {
  std::vector<std::string> tokens;
  std::string token;
  while (line >> token) tokens.push_back(token);
  return tokens;
}

// The per-field lines as written, checked together once the header is read.
struct FieldLines {
  std::vector<std::string> names, sizes, types, counts;
  bool points_seen = false;
};

// Parses one header line into `lines` and `header`; returns true on the DATA line.
bool ParseLine(const std::string& path,
               int number,
               const std::string& text,
               FieldLines* lines,
               PcdHeader* header) {
  std::istringstream line(text);
  std::string keyword;
  line >> keyword;
  if (keyword.empty() || keyword[0] == '#') return false;
  const std::vector<std::string> values = Tokens(line);
  auto one = [&]() -> const std::string& {
    if (values.size() != 1) FailAt(path, number, keyword + " needs one value");
    return values[0];
  };
  if (keyword == "VERSION" || keyword == "VIEWPOINT") return false;
  if (keyword == "FIELDS" || keyword == "COLUMNS") {
    lines->names = values;
  } else if (keyword == "SIZE") {
    lines->sizes = values;
  } else if (keyword == "TYPE") {
    lines->types = values;
  } else if (keyword == "COUNT") {
    lines->counts = values;
  } else if (keyword == "WIDTH") {
    header->width = ParseCount(path, number, one());
  } else if (keyword == "HEIGHT") {
    header->height = ParseCount(path, number, one());
  } else if (keyword == "POINTS") {
    header->num_points = ParseCount(path, number, one());
    lines->points_seen = true;
  } else if (keyword == "DATA") {
    header->data = one();
    if (header->data != "ascii" && header->data != "binary" &&
        header->data != "binary_compressed") {
      FailAt(path, number, "unknown DATA '" + header->data + "'");
    }
    return true;
  } else {
    FailAt(path, number, "unknown keyword '" + keyword.substr(0, 40) + "' (not a PCD header)");
  }
  return false;
}

// Builds the field list from the FIELDS/SIZE/TYPE/COUNT lines and checks each field.
void BuildFields(const std::string& path, const FieldLines& lines, PcdHeader* header) {
  const std::vector<std::string>&names = lines.names, &sizes = lines.sizes, &types = lines.types,
        &counts = lines.counts;
  if (names.empty()) Fail(path, "PCD header has no FIELDS");
  if (sizes.size() != names.size() || types.size() != names.size() ||
      (!counts.empty() && counts.size() != names.size())) {
    Fail(path,
         "PCD header lists " + std::to_string(names.size()) + " FIELDS but " +
             std::to_string(sizes.size()) + " SIZE, " + std::to_string(types.size()) + " TYPE, " +
             std::to_string(counts.size()) + " COUNT values");
  }
  for (size_t i = 0; i < names.size(); ++i) {
    PcdField field;
    field.name = names[i];
    field.size = sizes[i] == "1"   ? 1
                 : sizes[i] == "2" ? 2
                 : sizes[i] == "4" ? 4
                 : sizes[i] == "8" ? 8
                                   : 0;
    field.type = types[i].size() == 1 ? types[i][0] : 0;
    const bool valid_type = field.type == 'I' || field.type == 'U' ||
                            (field.type == 'F' && (field.size == 4 || field.size == 8));
    if (field.size == 0 || !valid_type) {
      Fail(path,
           "PCD field '" + field.name + "' has SIZE " + sizes[i] + " and TYPE " + types[i] +
               " (expected SIZE 1/2/4/8, TYPE I/U/F)");
    }
    if (!counts.empty()) {
      const uint64_t count = ParseCount(path, 0, counts[i]);
      if (count == 0 || count > 4096) {
        Fail(path, "PCD field '" + field.name + "' has COUNT " + counts[i]);
      }
      field.count = static_cast<int>(count);
    }
    header->point_step += static_cast<uint64_t>(field.size) * field.count;
    header->fields.push_back(field);
  }
}

// Checks that the data section can hold the points the header claims, without reading it.
void CheckDataSize(const std::string& path, std::ifstream& file, const PcdHeader& header) {
  const uint64_t file_bytes = std::filesystem::file_size(path);
  const uint64_t data_bytes = file_bytes - header.data_offset;
  const uint64_t max_points = std::numeric_limits<uint64_t>::max() / (header.point_step + 1);
  if (header.num_points > max_points) Fail(path, "PCD header claims too many points");
  const uint64_t needed = header.num_points * header.point_step;
  const std::string claim = std::to_string(header.num_points) + " points of " +
                            std::to_string(header.point_step) + " bytes";
  if (header.data == "binary" && data_bytes < needed) {
    Fail(path,
         "truncated: " + claim + " need " + std::to_string(needed) + " bytes, the file has " +
             std::to_string(data_bytes) + " after its header");
  }
  if (header.data == "ascii") {
    uint64_t values = 0;
    for (const PcdField& f : header.fields) values += f.count;
    if (data_bytes / 2 / values < header.num_points) {
      Fail(path, "truncated: " + claim + " cannot fit in " + std::to_string(data_bytes) + " bytes");
    }
  }
  if (header.data == "binary_compressed") {
    uint32_t sizes[2] = {0, 0};
    file.seekg(static_cast<std::streamoff>(header.data_offset));
    if (data_bytes < 8 || !file.read(reinterpret_cast<char*>(sizes), 8)) {
      Fail(path, "truncated: no compressed sizes after the header");
    }
    if (sizes[0] > data_bytes - 8) {
      Fail(path,
           "truncated: " + std::to_string(sizes[0]) + " compressed bytes announced, " +
               std::to_string(data_bytes - 8) + " present");
    }
    if (sizes[1] != needed || needed > kMaxLzfExpansion * (uint64_t(sizes[0]) + 16)) {
      Fail(path,
           claim + " do not match the stored sizes (" + std::to_string(sizes[0]) + " compressed, " +
               std::to_string(sizes[1]) + " uncompressed bytes)");
    }
  }
}

// PCL's header parser does not stop at DATA: it goes on reading lines that are empty, comments or start
// with a header keyword (a prefix match: "DATA1", "COLUMNSx"), and acts on them (a stray "COLUMNS" line
// made it crash). A data section that PCL would take for header lines is refused.
void CheckDataDoesNotLookLikeHeader(const std::string& path,
                                    const std::string& prefix,
                                    size_t begin,
                                    int line) {
  static const char* kKeywords[] = {"VERSION",
                                    "FIELDS",
                                    "COLUMNS",
                                    "SIZE",
                                    "TYPE",
                                    "COUNT",
                                    "WIDTH",
                                    "HEIGHT",
                                    "VIEWPOINT",
                                    "POINTS",
                                    "DATA"};
  while (begin < prefix.size()) {
    const std::string text = NextLine(prefix, &begin);
    ++line;
    const size_t first = text.find_first_not_of("\t\r ");
    if (text.empty()) continue;
    const std::string token =
        first == 0 ? text.substr(0, text.find_first_of("\t\r ")) : std::string();
    if (token.rfind('#', 0) == 0) continue;
    for (const char* keyword : kKeywords) {
      if (token.rfind(keyword, 0) == 0) {
        FailAt(path,
               line,
               "the data after DATA starts with '" + std::string(keyword) +
                   "', which PCL would read as a header line");
      }
    }
    return;
  }
}

}  // namespace

PcdHeader ReadPcdHeader(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) Fail(path, "cannot open the file");
  // The header is read from a bounded prefix: a file without newlines is never read whole.
  std::string prefix(kMaxHeaderBytes, '\0');
  file.read(prefix.data(), static_cast<std::streamsize>(prefix.size()));
  prefix.resize(static_cast<size_t>(file.gcount()));
  file.clear();
  PcdHeader header;
  FieldLines lines;
  bool data_seen = false;
  size_t begin = 0;
  int data_line = 0;
  for (int number = 1; !data_seen && begin < prefix.size(); ++number) {
    std::string text = NextLine(prefix, &begin);
    if (text.find('\0') != std::string::npos) {
      FailAt(path, number, "binary bytes (not a PCD header)");
    }
    if (!text.empty() && text.back() == '\r') text.pop_back();
    data_seen = ParseLine(path, number, text, &lines, &header);
    data_line = number;
  }
  if (!data_seen) Fail(path, "no DATA line in the PCD header (not a PCD file, or truncated)");
  CheckDataDoesNotLookLikeHeader(path, prefix, begin, data_line);
  header.data_offset = std::min<uint64_t>(begin, std::filesystem::file_size(path));
  BuildFields(path, lines, &header);
  if (header.width == 0 || header.height == 0) Fail(path, "PCD header has WIDTH or HEIGHT 0");
  if (header.width > (uint64_t(1) << 40) / header.height) {
    Fail(path, "PCD WIDTH x HEIGHT overflows");
  }
  if (!lines.points_seen) Fail(path, "PCD header has no POINTS line");
  if (header.num_points != header.width * header.height) {
    Fail(path,
         "PCD header has POINTS " + std::to_string(header.num_points) +
             " but WIDTH x HEIGHT = " + std::to_string(header.width * header.height));
  }
  CheckDataSize(path, file, header);
  return header;
}

}  // namespace colmap_lidar
