#include "colmap_ext/trajectory_files.h"

#include "colmap_ext/station_dataset.h"
#include "colmap_ext/text_lines.h"
#include "lidar/util/atomic_file.h"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// A rotation read from a file: orthonormal to 1e-3 (KITTI writes 7 digits), then re-orthonormalised.
Eigen::Quaterniond RotationFromMatrix(const Eigen::Matrix3d& rotation,
                                      const std::string& path,
                                      size_t line_number) {
  if (!(rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).isZero(1e-3) ||
      rotation.determinant() < 0) {
    FailAtLine(path, line_number, "the 3x3 block is not a rotation");
  }
  return Eigen::Quaterniond(rotation).normalized();
}

bool IsNumber(const std::string& token) {
  size_t used = 0;
  try {
    std::stod(token, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == token.size();
}

std::string FirstDataLine(const std::string& path, size_t* line_number) {
  std::string first;
  try {
    ForEachDataLine(path, [&](const std::string& line, size_t number) {
      if (!first.empty()) return;
      first = line;
      *line_number = number;
    });
  } catch (const std::runtime_error&) {
    throw std::runtime_error("cannot open the trajectory file " + path);
  }
  if (first.empty()) throw std::runtime_error(path + ": no pose line");
  return first;
}

std::string TimeText(double seconds) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(9) << seconds;
  return text.str();
}

double TumTime(const Trajectory& trajectory, size_t i) {
  if (!trajectory.times.empty()) return trajectory.times[i];
  const std::string& name = i < trajectory.names.size() ? trajectory.names[i] : "";
  if (!name.empty() && name.find_first_not_of("0123456789") == std::string::npos) {
    return std::stod(name);
  }
  return static_cast<double>(i);
}

}  // namespace

TrajectoryFileFormat DetectTrajectoryFileFormat(const std::string& path) {
  size_t line_number = 0;
  const std::string line = FirstDataLine(path, &line_number);
  std::istringstream stream(line);
  std::vector<std::string> tokens;
  for (std::string token; stream >> token;) tokens.push_back(token);
  bool all_numbers = true;
  for (const std::string& token : tokens) all_numbers &= IsNumber(token);
  if (all_numbers && tokens.size() == 12) return TrajectoryFileFormat::kKitti;
  // Eight tokens: TUM has its unit quaternion last, a named file after the name (numeric station
  // names such as 000034 read as numbers too).
  const auto unit_quaternion = [&](size_t first) {
    double squared = 0;
    for (size_t k = first; k < first + 4; ++k) squared += std::pow(std::stod(tokens[k]), 2);
    return std::abs(squared - 1) < 1e-3;
  };
  if (all_numbers && tokens.size() == 8 && unit_quaternion(4) && !unit_quaternion(1)) {
    return TrajectoryFileFormat::kTum;
  }
  if (tokens.size() == 8) {
    const std::string stem = fs::path(path).stem().string();
    const bool from_world = stem.size() >= 11 && stem.substr(stem.size() - 11) == "_from_world";
    return from_world ? TrajectoryFileFormat::kNamedSensorFromWorld
                      : TrajectoryFileFormat::kNamedWorldFromSensor;
  }
  FailAtLine(path,
             line_number,
             "not a trajectory line (KITTI: 12 numbers; TUM: 8 numbers; named: a station and "
             "qw qx qy qz tx ty tz)");
}

TrajectoryFileFormat TrajectoryFileFormatFromName(const std::string& name) {
  return ChoiceFromName(kTrajectoryFileFormatNames, name, "trajectory format");
}

std::string TrajectoryFileFormatName(TrajectoryFileFormat format) {
  return ChoiceName(kTrajectoryFileFormatNames, format);
}

Trajectory ReadTrajectoryFile(const std::string& path, TrajectoryFileFormat format) {
  Trajectory trajectory;
  if (format == TrajectoryFileFormat::kTum) return ReadTumTrajectory(path);
  if (format == TrajectoryFileFormat::kKitti) {
    trajectory.world_from_sensor = ReadKittiPoses(path);
    for (size_t i = 0; i < trajectory.Size(); ++i) trajectory.names.push_back(std::to_string(i));
    return trajectory;
  }
  for (const auto& [name, pose] : ReadNamedPoses(path)) {
    trajectory.names.push_back(name);
    trajectory.world_from_sensor.push_back(
        format == TrajectoryFileFormat::kNamedSensorFromWorld ? colmap::Inverse(pose) : pose);
  }
  if (trajectory.Size() == 0) throw std::runtime_error(path + ": no pose line");
  return trajectory;
}

std::vector<colmap::Rigid3d> ReadKittiPoses(const std::string& path, size_t min_count) {
  std::vector<colmap::Rigid3d> poses;
  size_t last_line = 0;
  ForEachDataLine(path, [&](const std::string& line, size_t number) {
    const std::vector<double> v = ParseNumberLine(line, path, number, 12);
    const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> pose(v.data());
    poses.emplace_back(RotationFromMatrix(pose.leftCols<3>(), path, number), pose.col(3));
    last_line = number;
  });
  if (poses.empty()) throw std::runtime_error(path + ": no pose line");
  CheckEnoughLines(path, last_line, poses.size(), min_count, "poses");
  return poses;
}

void WriteKittiPoses(const std::string& path,
                     const std::vector<colmap::Rigid3d>& world_from_sensor) {
  std::ostringstream out;
  out << std::scientific << std::setprecision(9);
  for (const colmap::Rigid3d& pose : world_from_sensor) {
    const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> matrix = pose.ToMatrix();
    for (int k = 0; k < 12; ++k) out << (k ? " " : "") << matrix.data()[k];
    out << "\n";
  }
  WriteFileAtomically(path, out.str());
}

Trajectory ReadTumTrajectory(const std::string& path) {
  Trajectory trajectory;
  ForEachDataLine(path, [&](const std::string& line, size_t number) {
    const std::vector<double> v = ParseNumberLine(line, path, number, 8);
    if (!trajectory.times.empty() && !(v[0] > trajectory.times.back())) {
      FailAtLine(path, number, "timestamp " + TimeText(v[0]) + " is not after the one before");
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1) > 1e-3) FailAtLine(path, number, "not a unit quaternion");
    trajectory.times.push_back(v[0]);
    trajectory.world_from_sensor.emplace_back(q.normalized(), Eigen::Vector3d(v[1], v[2], v[3]));
  });
  if (trajectory.Size() == 0) throw std::runtime_error(path + ": no pose line");
  return trajectory;
}

void WriteTumTrajectory(const std::string& path, const Trajectory& trajectory) {
  std::ostringstream out;
  out << "# timestamp tx ty tz qx qy qz qw   (world_from_sensor)\n" << std::setprecision(12);
  for (size_t i = 0; i < trajectory.Size(); ++i) {
    const colmap::Rigid3d& pose = trajectory.world_from_sensor[i];
    const Eigen::Quaterniond& q = pose.rotation;
    out << TimeText(TumTime(trajectory, i)) << " " << pose.translation.x() << " "
        << pose.translation.y() << " " << pose.translation.z() << " " << q.x() << " " << q.y()
        << " " << q.z() << " " << q.w() << "\n";
  }
  WriteFileAtomically(path, out.str());
}

std::vector<double> ReadKittiTimes(const std::string& path, size_t min_count) {
  std::vector<double> times;
  size_t last_line = 0;
  ForEachDataLine(path, [&](const std::string& line, size_t number) {
    const double time = ParseNumberLine(line, path, number, 1)[0];
    if (!times.empty() && !(time > times.back())) {
      FailAtLine(path, number, "time " + TimeText(time) + " is not after the one before");
    }
    times.push_back(time);
    last_line = number;
  });
  if (times.empty()) throw std::runtime_error(path + ": no time line");
  CheckEnoughLines(path, last_line, times.size(), min_count, "times");
  return times;
}

void WriteTrajectoryExports(const std::string& prefix, const Trajectory& trajectory) {
  WriteKittiPoses(prefix + "_kitti.txt", trajectory.world_from_sensor);
  WriteTumTrajectory(prefix + "_tum.txt", trajectory);
}

}  // namespace colmap_lidar
