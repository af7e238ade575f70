// Trajectory files in the formats other tools read and write, beside our named pose files
// (colmap_ext/station_dataset.h):
//   KITTI odometry poses  one line per frame: the 3x4 row-major [R | t] of world_from_cam (the
//                         line's index is the frame's), as in the odometry benchmark's poses/NN.txt
//   TUM RGB-D             "timestamp tx ty tz qx qy qz qw" per line, world_from_sensor (quaternion
//                         w last, as that format has it); '#' comments
//   KITTI times           one time [s] per line (the odometry benchmark's times.txt)
// Every reader throws std::runtime_error naming the file and line of a bad value.
#pragma once

#include "lidar/util/named_choice.h"

#include "colmap/geometry/rigid3.h"

#include <string>
#include <vector>

namespace colmap_lidar {

// A sequence of sensor poses. `names` are station names (frame indices as text for KITTI files,
// empty for TUM files); `times` are seconds (empty when the source has none).
struct Trajectory {
  std::vector<std::string> names;
  std::vector<double> times;
  std::vector<colmap::Rigid3d> world_from_sensor;

  size_t Size() const { return world_from_sensor.size(); }
};

enum class TrajectoryFileFormat {
  kNamedWorldFromSensor,  // "<station> qw qx qy qz tx ty tz" of world_from_sensor (lidar_poses.txt)
  kNamedSensorFromWorld,  // the same of sensor_from_world (ground_truth/cam_from_world.txt)
  kKitti,
  kTum,
};

// The format of a text file from its first data line: 12 numbers KITTI, 8 numbers TUM, a name and 7
// numbers a named file, whose direction follows the file name ("..._from_world.txt":
// sensor_from_world, otherwise world_from_sensor). Throws naming the file when none fits.
TrajectoryFileFormat DetectTrajectoryFileFormat(const std::string& path);
inline constexpr NamedChoices<TrajectoryFileFormat, 4> kTrajectoryFileFormatNames = {
    {{"named_world_from_sensor", TrajectoryFileFormat::kNamedWorldFromSensor},
     {"named_sensor_from_world", TrajectoryFileFormat::kNamedSensorFromWorld},
     {"kitti", TrajectoryFileFormat::kKitti},
     {"tum", TrajectoryFileFormat::kTum}}};
// Throws std::invalid_argument on a name not in kTrajectoryFileFormatNames.
TrajectoryFileFormat TrajectoryFileFormatFromName(const std::string& name);
std::string TrajectoryFileFormatName(TrajectoryFileFormat format);

Trajectory ReadTrajectoryFile(const std::string& path, TrajectoryFileFormat format);

// world_from_cam per line; at least `min_count` lines (a sequence's frames index into the file).
std::vector<colmap::Rigid3d> ReadKittiPoses(const std::string& path, size_t min_count = 0);
void WriteKittiPoses(const std::string& path,
                     const std::vector<colmap::Rigid3d>& world_from_sensor);

Trajectory ReadTumTrajectory(const std::string& path);
// Times from `trajectory.times`, else from numeric names, else the index.
void WriteTumTrajectory(const std::string& path, const Trajectory& trajectory);

// Strictly increasing times; at least `min_count` lines.
std::vector<double> ReadKittiTimes(const std::string& path, size_t min_count = 0);

// PREFIX_kitti.txt and PREFIX_tum.txt of the trajectory (station order), for the usual tools.
void WriteTrajectoryExports(const std::string& prefix, const Trajectory& trajectory);

}  // namespace colmap_lidar
