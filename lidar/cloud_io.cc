#include "lidar/cloud_io.h"

#include "lidar/pcd_header.h"
#include "lidar/util/atomic_file.h"
#include "lidar/util/statistics.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void Fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error("Cannot read point cloud " + path + ": " + problem);
}

std::string LowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext;
}

// Accumulates points, dropping non-finite ones and counting them.
class CloudBuilder {
 public:
  CloudBuilder(bool normals, bool colors, bool intensities, bool times = false)
      : normals_(normals), colors_(colors), intensities_(intensities), times_(times) {}

  // Callers pass a count the file's bytes can hold, never a header's bare claim.
  void Reserve(size_t num_points) {
    cloud_.Reserve(num_points, normals_, colors_, intensities_);
    if (times_) cloud_.times.reserve(num_points);
  }

  void Add(const Eigen::Vector3d& point,
           const Eigen::Vector3d& normal,
           const Color3ub& color,
           float intensity,
           double time = 0) {
    ++num_read_;
    if (!point.allFinite() || (normals_ && !normal.allFinite())) {
      ++num_dropped_;
      return;
    }
    if (times_ && !std::isfinite(time)) ++num_non_finite_times_;
    cloud_.points.push_back(point);
    if (normals_) cloud_.normals.push_back(normal);
    if (colors_) cloud_.colors.push_back(color);
    if (intensities_) cloud_.intensities.push_back(intensity);
    if (times_) cloud_.times.push_back(time);
  }

  PointCloud Finish(const std::string& path, CloudReadStats* stats) {
    if (num_read_ == 0) Fail(path, "the file holds no points");
    if (cloud_.Empty()) {
      Fail(path, "all " + std::to_string(num_read_) + " points are NaN or infinite");
    }
    if (num_non_finite_times_ > 0) {
      Fail(path,
           std::to_string(num_non_finite_times_) +
               " points have a NaN or infinite time (the per-point time field)");
    }
    if (stats) {
      stats->num_read = num_read_;
      stats->num_dropped_non_finite = num_dropped_;
    }
    return std::move(cloud_);
  }

 private:
  bool normals_, colors_, intensities_, times_;
  size_t num_read_ = 0;
  size_t num_dropped_ = 0;
  size_t num_non_finite_times_ = 0;
  PointCloud cloud_;
};

// ---------------------------------------------------------------- PCD (PCL)

double ReadPcdValue(const pcl::PCLPointField& field, const uint8_t* data) {
  switch (field.datatype) {
    case pcl::PCLPointField::FLOAT32: {
      float v;
      std::memcpy(&v, data, 4);
      return v;
    }
    case pcl::PCLPointField::FLOAT64: {
      double v;
      std::memcpy(&v, data, 8);
      return v;
    }
    case pcl::PCLPointField::UINT8:
      return *data;
    case pcl::PCLPointField::INT8:
      return static_cast<int8_t>(*data);
    case pcl::PCLPointField::UINT16: {
      uint16_t v;
      std::memcpy(&v, data, 2);
      return v;
    }
    case pcl::PCLPointField::INT16: {
      int16_t v;
      std::memcpy(&v, data, 2);
      return v;
    }
    case pcl::PCLPointField::UINT32: {
      uint32_t v;
      std::memcpy(&v, data, 4);
      return v;
    }
    case pcl::PCLPointField::INT32: {
      int32_t v;
      std::memcpy(&v, data, 4);
      return v;
    }
    default:
      return std::nan("");
  }
}

// Bytes of one value of a PCL field type (4: FLOAT32, INT32, UINT32).
int PcdValueBytes(const pcl::PCLPointField& field) {
  switch (field.datatype) {
    case pcl::PCLPointField::INT8:
    case pcl::PCLPointField::UINT8:
      return 1;
    case pcl::PCLPointField::INT16:
    case pcl::PCLPointField::UINT16:
      return 2;
    case pcl::PCLPointField::FLOAT64:
      return 8;
    default:
      return 4;
  }
}

// Where each attribute of a point lies in a PCD record (null: absent); every field is checked to
// lie inside the record.
struct PcdFields {
  PcdFields(const std::string& path, const pcl::PCLPointCloud2& blob) {
    const auto find = [&](std::initializer_list<const char*> names) -> const pcl::PCLPointField* {
      for (const char* name : names) {
        for (const auto& f : blob.fields) {
          if (f.name == name) return &f;
        }
      }
      return nullptr;
    };
    x = find({"x"}), y = find({"y"}), z = find({"z"});
    if (!x || !y || !z) Fail(path, "no x, y, z fields");
    intensity = find({"intensity"});
    time = find({"t", "time", "timestamp"});
    nx = find({"normal_x"}), ny = find({"normal_y"}), nz = find({"normal_z"});
    rgb = find({"rgb", "rgba"});
    for (const pcl::PCLPointField* field : {x, y, z, intensity, time, nx, ny, nz, rgb}) {
      if (field &&
          field->offset + std::max(PcdValueBytes(*field), field == rgb ? 4 : 0) > blob.point_step) {
        Fail(path, "field '" + field->name + "' lies outside the point record");
      }
    }
  }
  bool HasNormals() const { return nx && ny && nz; }

  const pcl::PCLPointField *x, *y, *z, *intensity, *time, *nx, *ny, *nz, *rgb;
};

// The point of the PCD record at `record` into `builder`.
void AddPcdPoint(const PcdFields& fields, const uint8_t* record, CloudBuilder* builder) {
  const auto value = [&](const pcl::PCLPointField* field) {
    return ReadPcdValue(*field, record + field->offset);
  };
  const Eigen::Vector3d point(value(fields.x), value(fields.y), value(fields.z));
  const Eigen::Vector3d normal =
      fields.HasNormals() ? Eigen::Vector3d(value(fields.nx), value(fields.ny), value(fields.nz))
                          : Eigen::Vector3d::Zero();
  Color3ub color(0, 0, 0);
  if (fields.rgb) {
    uint32_t rgb;
    std::memcpy(&rgb, record + fields.rgb->offset, 4);
    color = Color3ub((rgb >> 16) & 0xff, (rgb >> 8) & 0xff, rgb & 0xff);
  }
  builder->Add(point,
               normal,
               color,
               fields.intensity ? static_cast<float>(value(fields.intensity)) : 0.f,
               fields.time ? value(fields.time) : 0.0);
}

PointCloud ReadPcd(const std::string& path, CloudReadStats* stats) {
  // Our own check first: PCL's reader trusts the header (random bytes crash it).
  const PcdHeader header = ReadPcdHeader(path);
  pcl::PCLPointCloud2 blob;
  pcl::PCDReader reader;
  int status = -1;
  // PCL throws on some headers ours accepted (std::out_of_range); the fuzzers found one.
  try {
    status = reader.read(path, blob);
  } catch (const std::exception& error) {
    Fail(path, std::string("PCL's PCD reader failed: ") + error.what());
  }
  if (status < 0) {
    Fail(path, "PCL's PCD reader rejected it (truncated or malformed; see the message above)");
  }
  const PcdFields fields(path, blob);
  const size_t num_points = static_cast<size_t>(blob.width) * blob.height;
  if (num_points != header.num_points || blob.data.size() < num_points * blob.point_step) {
    Fail(path, "truncated data section");
  }
  CloudBuilder builder(fields.HasNormals(),
                       fields.rgb != nullptr,
                       fields.intensity != nullptr,
                       fields.time != nullptr);
  for (size_t i = 0; i < num_points; ++i) {
    AddPcdPoint(fields, blob.data.data() + i * blob.point_step, &builder);
  }
  return builder.Finish(path, stats);
}

// ---------------------------------------------------------------- PLY

enum class PlyType {
  kUnknown,
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};

struct PlyProperty {
  std::string name;
  std::string type;
  PlyType kind = PlyType::kUnknown;
  int size = 0;
};

// Both spellings of the PLY specification (char, int8, ...).
PlyType ParsePlyType(const std::string& type) {
  static const std::map<std::string, PlyType> kTypes = {{"char", PlyType::kInt8},
                                                        {"int8", PlyType::kInt8},
                                                        {"uchar", PlyType::kUint8},
                                                        {"uint8", PlyType::kUint8},
                                                        {"short", PlyType::kInt16},
                                                        {"int16", PlyType::kInt16},
                                                        {"ushort", PlyType::kUint16},
                                                        {"uint16", PlyType::kUint16},
                                                        {"int", PlyType::kInt32},
                                                        {"int32", PlyType::kInt32},
                                                        {"uint", PlyType::kUint32},
                                                        {"uint32", PlyType::kUint32},
                                                        {"float", PlyType::kFloat32},
                                                        {"float32", PlyType::kFloat32},
                                                        {"double", PlyType::kFloat64},
                                                        {"float64", PlyType::kFloat64}};
  const auto found = kTypes.find(type);
  return found == kTypes.end() ? PlyType::kUnknown : found->second;
}

int PlyTypeSize(PlyType kind) {
  switch (kind) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
    default:
      return 0;
  }
}

template <typename T>
double DecodeAs(const char* bytes) {
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return static_cast<double>(value);
}

double DecodePly(const PlyProperty& property, const char* data, bool swap) {
  char buffer[8];
  std::memcpy(buffer, data, property.size);
  if (swap) std::reverse(buffer, buffer + property.size);
  switch (property.kind) {
    case PlyType::kInt8:
      return DecodeAs<int8_t>(buffer);
    case PlyType::kUint8:
      return DecodeAs<uint8_t>(buffer);
    case PlyType::kInt16:
      return DecodeAs<int16_t>(buffer);
    case PlyType::kUint16:
      return DecodeAs<uint16_t>(buffer);
    case PlyType::kInt32:
      return DecodeAs<int32_t>(buffer);
    case PlyType::kUint32:
      return DecodeAs<uint32_t>(buffer);
    case PlyType::kFloat32:
      return DecodeAs<float>(buffer);
    default:
      return DecodeAs<double>(buffer);
  }
}

struct PlyHeader {
  std::string format;  // ascii | binary_little_endian | binary_big_endian
  size_t num_vertices = 0;
  std::vector<PlyProperty> properties;  // of the vertex element
  bool vertex_seen = false;             // while parsing: the vertex element came
};

void ParsePlyHeaderLine(const std::string& path,
                        const std::string& line,
                        bool* in_vertex,
                        PlyHeader* header) {
  std::istringstream tokens(line);
  std::string keyword;
  tokens >> keyword;
  if (keyword == "format") {
    tokens >> header->format;
  } else if (keyword == "element") {
    std::string name;
    size_t count = 0;
    tokens >> name >> count;
    *in_vertex = name == "vertex";
    if (*in_vertex) {
      header->num_vertices = count;
      header->vertex_seen = true;
    } else if (!header->vertex_seen) {
      Fail(path, "element '" + name + "' before 'vertex' is not supported");
    }
  } else if (keyword == "property" && *in_vertex) {
    PlyProperty property;
    tokens >> property.type;
    if (property.type == "list") Fail(path, "list property in vertex element");
    tokens >> property.name;
    property.kind = ParsePlyType(property.type);
    property.size = PlyTypeSize(property.kind);
    if (property.size == 0) Fail(path, "unknown property type '" + property.type + "'");
    header->properties.push_back(property);
  }
}

// The header up to and including end_header; the stream is left at the first vertex.
PlyHeader ReadPlyHeader(const std::string& path, std::istream& file) {
  std::string line;
  std::getline(file, line);
  if (line.rfind("ply", 0) != 0) Fail(path, "not a PLY file (no 'ply' magic)");
  PlyHeader header;
  bool in_vertex = false;
  while (std::getline(file, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("end_header", 0) == 0) break;
    ParsePlyHeaderLine(path, line, &in_vertex, &header);
  }
  if (line.rfind("end_header", 0) != 0) Fail(path, "no end_header");
  if (header.format != "ascii" && header.format != "binary_little_endian" &&
      header.format != "binary_big_endian") {
    Fail(path, "unknown format '" + header.format + "'");
  }
  return header;
}

// Where each field of a point lies among the vertex properties (-1: absent).
struct PlyFields {
  explicit PlyFields(const std::vector<PlyProperty>& properties) {
    auto index_of = [&](std::initializer_list<const char*> names) {
      for (size_t i = 0; i < properties.size(); ++i) {
        for (const char* n : names) {
          if (properties[i].name == n) return static_cast<int>(i);
        }
      }
      return -1;
    };
    xyz = {index_of({"x"}), index_of({"y"}), index_of({"z"})};
    normal = {
        index_of({"nx", "normal_x"}), index_of({"ny", "normal_y"}), index_of({"nz", "normal_z"})};
    rgb = {index_of({"red", "r"}), index_of({"green", "g"}), index_of({"blue", "b"})};
    intensity = index_of({"intensity", "scalar_intensity", "scalar_Intensity"});
    time = index_of({"t", "time", "timestamp"});
  }
  static bool All(const std::array<int, 3>& fields) {
    return fields[0] >= 0 && fields[1] >= 0 && fields[2] >= 0;
  }
  std::array<int, 3> xyz, normal, rgb;
  int intensity;
  int time;
};

void ReadPlyAsciiVertex(const std::string& path,
                        std::istream& file,
                        size_t v,
                        size_t num_vertices,
                        std::vector<double>* values) {
  std::string line;
  if (!std::getline(file, line)) {
    Fail(path,
         "truncated: " + std::to_string(v) + " of " + std::to_string(num_vertices) + " vertices");
  }
  std::istringstream tokens(line);
  for (double& value : *values) {
    std::string token;
    if (!(tokens >> token)) Fail(path, "vertex " + std::to_string(v) + " has too few values");
    try {
      value = std::stod(token);
    } catch (const std::exception&) {
      if (token != "nan" && token != "-nan") {
        Fail(path, "vertex " + std::to_string(v) + ": '" + token + "' is not a number");
      }
      value = std::nan("");
    }
  }
}

void ReadPlyBinaryVertex(const std::string& path,
                         std::istream& file,
                         const PlyHeader& header,
                         size_t v,
                         std::vector<char>* record,
                         std::vector<double>* values) {
  if (!file.read(record->data(), record->size())) {
    Fail(path,
         "truncated: " + std::to_string(v) + " of " + std::to_string(header.num_vertices) +
             " vertices");
  }
  const bool swap = header.format == "binary_big_endian";
  size_t offset = 0;
  for (size_t i = 0; i < header.properties.size(); ++i) {
    (*values)[i] = DecodePly(header.properties[i], record->data() + offset, swap);
    offset += header.properties[i].size;
  }
}

PointCloud ReadPly(const std::string& path, CloudReadStats* stats) {
  std::ifstream file(path, std::ios::binary);
  if (!file) Fail(path, "cannot open the file");
  const PlyHeader header = ReadPlyHeader(path, file);
  const PlyFields fields(header.properties);
  if (!PlyFields::All(fields.xyz)) Fail(path, "no x, y, z vertex properties");
  const bool normals = PlyFields::All(fields.normal);
  const bool colors = PlyFields::All(fields.rgb);
  CloudBuilder builder(normals, colors, fields.intensity >= 0, fields.time >= 0);
  std::vector<double> values(header.properties.size());
  size_t record_size = 0;
  for (const auto& p : header.properties) record_size += p.size;
  std::vector<char> record(record_size);
  if (header.format != "ascii" && record_size > 0) {
    const auto data_start = file.tellg();
    file.seekg(0, std::ios::end);
    const size_t num_bytes = static_cast<size_t>(file.tellg() - data_start);
    file.seekg(data_start);
    builder.Reserve(std::min(header.num_vertices, num_bytes / record_size));
  }
  auto vector_of = [&](const std::array<int, 3>& f) {
    return Eigen::Vector3d(values[f[0]], values[f[1]], values[f[2]]);
  };
  for (size_t v = 0; v < header.num_vertices; ++v) {
    if (header.format == "ascii") {
      ReadPlyAsciiVertex(path, file, v, header.num_vertices, &values);
    } else {
      ReadPlyBinaryVertex(path, file, header, v, &record, &values);
    }
    const Color3ub color = colors ? Color3ub(static_cast<uint8_t>(values[fields.rgb[0]]),
                                             static_cast<uint8_t>(values[fields.rgb[1]]),
                                             static_cast<uint8_t>(values[fields.rgb[2]]))
                                  : Color3ub(0, 0, 0);
    builder.Add(vector_of(fields.xyz),
                normals ? vector_of(fields.normal) : Eigen::Vector3d::Zero(),
                color,
                fields.intensity >= 0 ? static_cast<float>(values[fields.intensity]) : 0.f,
                fields.time >= 0 ? values[fields.time] : 0.0);
  }
  return builder.Finish(path, stats);
}

// ---------------------------------------------------------------- KITTI / text

PointCloud ReadKittiBin(const std::string& path, CloudReadStats* stats) {
  const auto num_bytes = fs::file_size(path);
  if (num_bytes % (4 * sizeof(float)) != 0) {
    Fail(path,
         "size " + std::to_string(num_bytes) +
             " bytes is not a multiple of 16 (float32 x y z i): "
             "truncated or not a KITTI .bin");
  }
  std::ifstream file(path, std::ios::binary);
  std::vector<float> data(num_bytes / sizeof(float));
  if (!file.read(reinterpret_cast<char*>(data.data()), num_bytes)) {
    Fail(path, "read error");
  }
  CloudBuilder builder(false, false, true);
  for (size_t i = 0; i + 3 < data.size(); i += 4) {
    builder.Add(Eigen::Vector3d(data[i], data[i + 1], data[i + 2]),
                Eigen::Vector3d::Zero(),
                Color3ub(0, 0, 0),
                data[i + 3]);
  }
  return builder.Finish(path, stats);
}

PointCloud ReadXyzText(const std::string& path, CloudReadStats* stats) {
  std::ifstream file(path);
  if (!file) Fail(path, "cannot open the file");
  std::string line;
  size_t line_number = 0;
  CloudBuilder* builder = nullptr;
  CloudBuilder with_i(false, false, true), without_i(false, false, false);
  while (std::getline(file, line)) {
    ++line_number;
    if (line.empty() || line[0] == '#' || line[0] == '/') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream tokens(line);
    std::vector<double> values;
    std::string token;
    while (tokens >> token) {
      try {
        values.push_back(std::stod(token));
      } catch (const std::exception&) {
        Fail(path, "line " + std::to_string(line_number) + ": '" + token + "' is not a number");
      }
    }
    if (values.size() < 3) {
      Fail(path, "line " + std::to_string(line_number) + " has fewer than 3 values");
    }
    if (!builder) builder = values.size() >= 4 ? &with_i : &without_i;
    builder->Add(Eigen::Vector3d(values[0], values[1], values[2]),
                 Eigen::Vector3d::Zero(),
                 Color3ub(0, 0, 0),
                 values.size() >= 4 ? static_cast<float>(values[3]) : 0.f);
  }
  return (builder ? builder : &without_i)->Finish(path, stats);
}

// ---------------------------------------------------------------- writers

void WritePcdBinary(std::ostream& out, const PointCloud& cloud) {
  std::string fields = "x y z", sizes = "4 4 4", types = "F F F", counts = "1 1 1";
  auto add = [&](const char* name, const char* type) {
    fields += std::string(" ") + name;
    sizes += " 4";
    types += std::string(" ") + type;
    counts += " 1";
  };
  if (cloud.HasIntensities()) add("intensity", "F");
  if (cloud.HasNormals()) {
    add("normal_x", "F");
    add("normal_y", "F");
    add("normal_z", "F");
  }
  if (cloud.HasColors()) add("rgb", "F");
  out << "# .PCD v0.7 - Point Cloud Data file format (written by "
         "colmap-lidar)\n"
      << "VERSION 0.7\nFIELDS " << fields << "\nSIZE " << sizes << "\nTYPE " << types << "\nCOUNT "
      << counts << "\nWIDTH " << cloud.Size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS "
      << cloud.Size() << "\nDATA binary\n";
  std::vector<float> row;
  for (size_t i = 0; i < cloud.Size(); ++i) {
    row.assign(cloud.points[i].data(), cloud.points[i].data() + 3);
    if (cloud.HasIntensities()) row.push_back(cloud.intensities[i]);
    if (cloud.HasNormals()) {
      for (int k = 0; k < 3; ++k) row.push_back(cloud.normals[i][k]);
    }
    if (cloud.HasColors()) {
      const uint32_t rgb = (uint32_t(cloud.colors[i][0]) << 16) |
                           (uint32_t(cloud.colors[i][1]) << 8) | cloud.colors[i][2];
      float packed;
      std::memcpy(&packed, &rgb, 4);
      row.push_back(packed);
    }
    out.write(reinterpret_cast<const char*>(row.data()), row.size() * sizeof(float));
  }
}

void WritePlyBinary(std::ostream& out, const PointCloud& cloud) {
  out << "ply\nformat binary_little_endian 1.0\ncomment written by "
         "colmap-lidar\nelement vertex "
      << cloud.Size() << "\nproperty float x\nproperty float y\nproperty float z\n";
  if (cloud.HasNormals()) {
    out << "property float nx\nproperty float ny\nproperty float nz\n";
  }
  if (cloud.HasColors()) {
    out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  }
  if (cloud.HasIntensities()) out << "property float intensity\n";
  out << "end_header\n";
  std::vector<char> row;
  auto put = [&row](const void* data, size_t n) {
    const char* bytes = static_cast<const char*>(data);
    row.insert(row.end(), bytes, bytes + n);
  };
  for (size_t i = 0; i < cloud.Size(); ++i) {
    row.clear();
    const Eigen::Vector3f p = cloud.points[i].cast<float>();
    put(p.data(), 12);
    if (cloud.HasNormals()) {
      const Eigen::Vector3f n = cloud.normals[i].cast<float>();
      put(n.data(), 12);
    }
    if (cloud.HasColors()) put(cloud.colors[i].data(), 3);
    if (cloud.HasIntensities()) put(&cloud.intensities[i], 4);
    out.write(row.data(), row.size());
  }
}

}  // namespace

PointCloud ReadPointCloud(const std::string& path, CloudReadStats* stats) {
  if (!fs::is_regular_file(path)) Fail(path, "no such file");
  if (fs::file_size(path) == 0) Fail(path, "the file is empty");
  const std::string ext = LowerExtension(path);
  if (ext == ".pcd") return ReadPcd(path, stats);
  if (ext == ".ply") return ReadPly(path, stats);
  if (ext == ".bin") return ReadKittiBin(path, stats);
  if (ext == ".xyz" || ext == ".txt") return ReadXyzText(path, stats);
  Fail(path, "unknown extension '" + ext + "' (expected .pcd .ply .bin .xyz .txt)");
}

PointCloud ReadStationCloud(const std::string& path, CloudReadStats* stats) {
  PointCloud cloud = ReadPointCloud(path, stats);
  std::vector<double> ranges;
  const size_t stride = std::max<size_t>(1, cloud.Size() / 10000);
  for (size_t i = 0; i < cloud.Size(); i += stride) ranges.push_back(cloud.points[i].norm());
  const double median = Median(std::move(ranges));
  if (median > kMaxMedianRangeM) {
    std::ostringstream problem;
    problem << "the median range from the sensor is " << std::fixed << std::setprecision(0)
            << median << " m; a station cloud must be in the LiDAR's frame in metres (is it in "
            << "millimetres, or in a world frame?)";
    Fail(path, problem.str());
  }
  return cloud;
}

void WritePointCloud(const std::string& path, const PointCloud& cloud) {
  cloud.CheckConsistent();
  const std::string ext = LowerExtension(path);
  if (ext != ".pcd" && ext != ".ply") {
    throw std::invalid_argument("Cannot write point cloud " + path +
                                ": extension must be .pcd or .ply");
  }
  WriteAtomically(path, [&](const std::string& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    if (!out) return false;
    if (ext == ".pcd") {
      WritePcdBinary(out, cloud);
    } else {
      WritePlyBinary(out, cloud);
    }
    out.flush();
    return static_cast<bool>(out);
  });
}

}  // namespace colmap_lidar
