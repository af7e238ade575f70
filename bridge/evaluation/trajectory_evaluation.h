// evaluate_trajectory's work: a trajectory against a reference, read from any of the formats of
// colmap_ext/trajectory_files.h or a COLMAP model (its images' camera poses, named by the station
// stem of the image name), matched frame by frame, evaluated by lidar/trajectory_error.h and written
// as OUTPUT/metrics.json, OUTPUT/top_view.png (both paths, the estimate coloured by its per-step
// translation error) and OUTPUT/step_errors.png (per-step translation and rotation errors).
#pragma once

#include "colmap_ext/trajectory_files.h"
#include "lidar/trajectory_error.h"
#include "lidar/util/named_choice.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/reconstruction.h"

#include <optional>
#include <string>
#include <vector>

namespace colmap_lidar {

// How a trajectory is read: by its path (a folder: a COLMAP model; a file: colmap_ext's
// DetectTrajectoryFileFormat), as a COLMAP model, or as a file of one of colmap_ext's formats (the
// names are TrajectoryFileFormatName's).
enum class TrajectorySource {
  kAuto,
  kColmapModel,
  kNamedWorldFromSensor,
  kNamedSensorFromWorld,
  kKitti,
  kTum
};
inline constexpr NamedChoices<TrajectorySource, 6> kTrajectorySourceNames = {
    {{"auto", TrajectorySource::kAuto},
     {"colmap", TrajectorySource::kColmapModel},
     {"named_world_from_sensor", TrajectorySource::kNamedWorldFromSensor},
     {"named_sensor_from_world", TrajectorySource::kNamedSensorFromWorld},
     {"kitti", TrajectorySource::kKitti},
     {"tum", TrajectorySource::kTum}}};

// Throws naming the path when it cannot be read.
Trajectory LoadTrajectory(const std::string& path, TrajectorySource source);

// The camera poses world_from_cam of a model's registered images, named by station, in name order.
Trajectory ModelCameraTrajectory(const colmap::Reconstruction& model);

// The dataset's timestamps.txt (station, time) attached to a named trajectory without times.
void AttachStationTimes(const std::vector<std::string>& stations,
                        const std::vector<double>& times,
                        Trajectory* trajectory);

struct MatchedTrajectories {
  std::vector<std::string> names;  // the reference's names (or times as text), in its order
  std::vector<Eigen::Isometry3d> estimate, reference;
  size_t num_estimate_unmatched = 0, num_reference_unmatched = 0;
  std::string matched_by;  // "name" or "time"
};

// Frames matched by name (numeric names by value: "000034" is "34") when both have names, else by
// the nearest time within `max_time_difference_s` when both have times; in the reference's order.
// Throws std::runtime_error naming both paths when fewer than 2 frames match.
MatchedTrajectories MatchTrajectories(const Trajectory& estimate,
                                      const std::string& estimate_path,
                                      const Trajectory& reference,
                                      const std::string& reference_path,
                                      double max_time_difference_s);

// Writes metrics.json and the two PNGs into OUTPUT (through OUTPUT.partial: all or nothing).
void WriteTrajectoryEvaluation(const std::string& output_path,
                               const MatchedTrajectories& matched,
                               const TrajectoryError& error,
                               const TrajectoryErrorOptions& options);

// One line for the console: relative translation (%) and rotation (deg/m), end-to-end drift, ATE.
std::string TrajectoryErrorSummary(const TrajectoryError& error);

}  // namespace colmap_lidar
