#include "colmap_ext/kitti_oxts.h"

#include "colmap_ext/text_lines.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace colmap_lidar {
namespace {

constexpr double kEarthRadiusM = 6378137.0;
constexpr int kPacketValues = 30;

double Radians(double degrees) { return degrees * M_PI / 180.0; }

// Days from 1970-01-01 to year-month-day of the proleptic Gregorian calendar (March-based years, so
// that the leap day ends a year).
int64_t DaysFromCivil(int64_t year, int64_t month, int64_t day) {
  year -= month <= 2 ? 1 : 0;
  const int64_t era = (year >= 0 ? year : year - 399) / 400;
  const int64_t year_of_era = year - era * 400;
  const int64_t day_of_year = (153 * (month + (month > 2 ? -3 : 9)) + 2) / 5 + day - 1;
  const int64_t day_of_era = year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
  return era * 146097 + day_of_era - 719468;
}

double ParseTimestamp(const std::string& line, const std::string& path, size_t line_number) {
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, consumed = 0;
  double second = NAN;
  const int read = std::sscanf(line.c_str(),
                               " %4d-%2d-%2d %2d:%2d:%lf %n",
                               &year,
                               &month,
                               &day,
                               &hour,
                               &minute,
                               &second,
                               &consumed);
  if (read != 6 || static_cast<size_t>(consumed) != line.size() || month < 1 || month > 12 ||
      day < 1 || day > 31 || hour > 23 || minute > 59 || !(second >= 0 && second < 61)) {
    FailAtLine(path, line_number, "not a timestamp 'YYYY-MM-DD hh:mm:ss.fffffffff': " + line);
  }
  return static_cast<double>(DaysFromCivil(year, month, day)) * 86400.0 + hour * 3600.0 +
         minute * 60.0 + second;
}

}  // namespace

OxtsPacket ReadOxtsPacket(const std::string& path) {
  std::vector<double> values;
  ForEachDataLine(path, [&](const std::string& line, size_t number) {
    if (!values.empty()) FailAtLine(path, number, "a second line; a packet is one line");
    values = ParseNumberLine(line, path, number, kPacketValues);
  });
  if (values.empty()) throw std::runtime_error(path + ": empty OXTS packet");
  OxtsPacket packet;
  packet.latitude_deg = values[0];
  packet.longitude_deg = values[1];
  packet.altitude_m = values[2];
  packet.roll_rad = values[3];
  packet.pitch_rad = values[4];
  packet.yaw_rad = values[5];
  if (std::abs(packet.latitude_deg) >= 90 || std::abs(packet.longitude_deg) > 180) {
    FailAtLine(path, 1, "latitude or longitude out of range");
  }
  return packet;
}

std::vector<colmap::Rigid3d> WorldFromImuFromOxts(const std::vector<OxtsPacket>& packets) {
  std::vector<colmap::Rigid3d> poses;
  if (packets.empty()) return poses;
  const double scale = std::cos(Radians(packets.front().latitude_deg));
  std::vector<colmap::Rigid3d> mercator_from_imu;
  for (const OxtsPacket& packet : packets) {
    const Eigen::Vector3d t(
        scale * kEarthRadiusM * Radians(packet.longitude_deg),
        scale * kEarthRadiusM * std::log(std::tan(Radians(90.0 + packet.latitude_deg) / 2.0)),
        packet.altitude_m);
    const Eigen::Quaterniond r = Eigen::AngleAxisd(packet.yaw_rad, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(packet.pitch_rad, Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(packet.roll_rad, Eigen::Vector3d::UnitX());
    mercator_from_imu.emplace_back(r, t);
  }
  const colmap::Rigid3d imu0_from_mercator = colmap::Inverse(mercator_from_imu.front());
  for (const colmap::Rigid3d& pose : mercator_from_imu) poses.push_back(imu0_from_mercator * pose);
  return poses;
}

std::vector<double> ReadKittiTimestamps(const std::string& path, size_t min_count) {
  std::vector<double> times;
  size_t last_line = 0;
  ForEachDataLine(path, [&](const std::string& line, size_t number) {
    const double time = ParseTimestamp(line, path, number);
    if (!times.empty() && !(time > times.back())) {
      FailAtLine(path, number, "timestamp " + line + " is not after the one before");
    }
    times.push_back(time);
    last_line = number;
  });
  CheckEnoughLines(path, last_line, times.size(), std::max<size_t>(min_count, 1), "timestamps");
  return times;
}

}  // namespace colmap_lidar
