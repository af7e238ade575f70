#include "bridge/evaluation/trajectory_evaluation.h"

#include "bridge/evaluation/calibration_evaluation.h"
#include "colmap_ext/rigid3_isometry.h"
#include "lidar/plot.h"
#include "lidar/util/atomic_file.h"

#include "colmap/scene/reconstruction.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

Trajectory LoadColmapModel(const std::string& path) {
  colmap::Reconstruction model;
  try {
    model.Read(path);
  } catch (const std::exception& error) {
    throw std::runtime_error(path + ": not a COLMAP model (" + error.what() + ")");
  }
  Trajectory trajectory = ModelCameraTrajectory(model);
  if (trajectory.Size() == 0) {
    throw std::runtime_error(path + ": a COLMAP model without registered images");
  }
  return trajectory;
}

// "000034" -> "34"; other names unchanged.
std::string MatchKey(const std::string& name) {
  if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) return name;
  const size_t first = name.find_first_not_of('0');
  return first == std::string::npos ? "0" : name.substr(first);
}

// Index into `estimate` per reference frame (-1: none).
std::vector<int> MatchByName(const Trajectory& estimate, const Trajectory& reference) {
  std::map<std::string, int> index;
  for (size_t k = 0; k < estimate.names.size(); ++k) index[MatchKey(estimate.names[k])] = k;
  std::vector<int> match;
  for (const std::string& name : reference.names) {
    const auto it = index.find(MatchKey(name));
    match.push_back(it == index.end() ? -1 : it->second);
  }
  return match;
}

std::vector<int> MatchByTime(const Trajectory& estimate,
                             const Trajectory& reference,
                             double max_dt) {
  // The estimate's times in increasing order with their indices (a station order need not be one).
  std::vector<std::pair<double, int>> times;
  for (size_t k = 0; k < estimate.times.size(); ++k) {
    times.emplace_back(estimate.times[k], static_cast<int>(k));
  }
  std::sort(times.begin(), times.end());
  std::vector<int> match;
  for (const double time : reference.times) {
    const auto after = std::lower_bound(
        times.begin(), times.end(), std::make_pair(time, std::numeric_limits<int>::min()));
    int best = -1;
    double best_dt = max_dt;
    for (auto candidate : {after, after == times.begin() ? after : after - 1}) {
      if (candidate == times.end() || std::abs(candidate->first - time) > best_dt) continue;
      best_dt = std::abs(candidate->first - time);
      best = candidate->second;
    }
    match.push_back(best);
  }
  return match;
}

std::string TimeName(double time) {
  std::ostringstream name;
  name << std::fixed << std::setprecision(6) << time;
  return name.str();
}

nlohmann::json ErrorJson(const TrajectoryError& error) {
  nlohmann::json json;
  json["num_poses"] = error.num_poses;
  json["path_length_m"] = error.path_length_m;
  const bool relative = error.num_segments > 0;
  json["relative"]["num_segments"] = error.num_segments;
  json["relative"]["translation_percent"] =
      relative ? nlohmann::json(error.translation_percent) : nlohmann::json();
  json["relative"]["rotation_deg_per_m"] =
      relative ? nlohmann::json(error.rotation_deg_per_m) : nlohmann::json();
  for (const SegmentLengthError& length : error.lengths) {
    json["relative"]["per_length"].push_back({{"length_m", length.length_m},
                                              {"count", length.count},
                                              {"translation_percent", length.translation_percent},
                                              {"rotation_deg_per_m", length.rotation_deg_per_m}});
  }
  json["end_to_end_drift_percent"] = error.end_to_end_drift_percent;
  json["absolute"] = {{"alignment_scale", error.alignment_scale},
                      {"position_rmse_m", error.position_rmse_m},
                      {"position_mean_m", error.position_mean_m},
                      {"position_median_m", error.position_median_m},
                      {"position_max_m", error.position_max_m}};
  return json;
}

nlohmann::json StepsJson(const MatchedTrajectories& matched, const TrajectoryError& error) {
  nlohmann::json steps = nlohmann::json::array();
  for (size_t k = 0; k < error.steps.size(); ++k) {
    const StepError& step = error.steps[k];
    steps.push_back({{"from", matched.names[k]},
                     {"to", matched.names[k + 1]},
                     {"length_m", step.length_m},
                     {"translation_error_m", step.translation_error_m},
                     {"rotation_error_deg", step.rotation_error_deg}});
  }
  return steps;
}

void WritePlots(const fs::path& folder,
                const MatchedTrajectories& matched,
                const TrajectoryError& error) {
  std::vector<Eigen::Vector3d> reference, estimate;
  std::vector<double> step_error = {0.0};
  for (const Eigen::Isometry3d& pose : matched.reference) reference.push_back(pose.translation());
  const Eigen::Isometry3d& align = error.reference_from_estimate;
  for (const Eigen::Isometry3d& pose : matched.estimate) {
    estimate.push_back(error.alignment_scale * (align.linear() * pose.translation()) +
                       align.translation());
  }
  PlotSeries translation{"t [cm]", {}, {}}, rotation{"r [0.01 deg]", {}, {}};
  for (const StepError& step : error.steps) {
    step_error.push_back(step.translation_error_m);
    translation.x.push_back(step.distance_m);
    translation.y.push_back(100 * step.translation_error_m);
    rotation.x.push_back(step.distance_m);
    rotation.y.push_back(100 * step.rotation_error_deg);
  }
  TopViewPlotOptions top;
  top.title = "Top view after the alignment (per-step translation error)";
  top.value_label = "step error [cm]";
  top.value_scale = 100;
  WriteTopViewPng((folder / "top_view.png").string(), reference, estimate, step_error, top);
  LinePlotOptions line;
  line.title = "Per-step error of the relative motion";
  line.x_label = "distance along the reference [m]";
  line.y_label = "error";
  WriteLinePlotPng((folder / "step_errors.png").string(), {translation, rotation}, line);
}

}  // namespace

Trajectory ModelCameraTrajectory(const colmap::Reconstruction& model) {
  std::map<std::string, colmap::Rigid3d> poses;
  for (const colmap::image_t image_id : model.RegImageIds()) {
    const colmap::Image& image = model.Image(image_id);
    poses[StationOfImageName(image.Name())] = colmap::Inverse(image.CamFromWorld());
  }
  Trajectory trajectory;
  for (const auto& [name, pose] : poses) {
    trajectory.names.push_back(name);
    trajectory.world_from_sensor.push_back(pose);
  }
  return trajectory;
}

Trajectory LoadTrajectory(const std::string& path, TrajectorySource source) {
  const bool automatic = source == TrajectorySource::kAuto;
  if (source == TrajectorySource::kColmapModel || (automatic && fs::is_directory(path))) {
    return LoadColmapModel(path);
  }
  if (!fs::is_regular_file(path)) throw std::runtime_error(path + ": no such trajectory file");
  const TrajectoryFileFormat file_format =
      automatic ? DetectTrajectoryFileFormat(path)
                : TrajectoryFileFormatFromName(ChoiceName(kTrajectorySourceNames, source));
  return ReadTrajectoryFile(path, file_format);
}

void AttachStationTimes(const std::vector<std::string>& stations,
                        const std::vector<double>& times,
                        Trajectory* trajectory) {
  if (!trajectory->times.empty() || trajectory->names.empty()) return;
  std::map<std::string, double> time_of;
  for (size_t k = 0; k < stations.size() && k < times.size(); ++k)
    time_of[MatchKey(stations[k])] = times[k];
  std::vector<double> attached;
  for (const std::string& name : trajectory->names) {
    const auto it = time_of.find(MatchKey(name));
    if (it == time_of.end()) return;  // not every frame has a time: match by name only
    attached.push_back(it->second);
  }
  trajectory->times = attached;
}

MatchedTrajectories MatchTrajectories(const Trajectory& estimate,
                                      const std::string& estimate_path,
                                      const Trajectory& reference,
                                      const std::string& reference_path,
                                      double max_time_difference_s) {
  MatchedTrajectories matched;
  std::vector<int> match;
  if (!estimate.names.empty() && !reference.names.empty()) {
    match = MatchByName(estimate, reference);
    matched.matched_by = "name";
  } else if (!estimate.times.empty() && !reference.times.empty()) {
    match = MatchByTime(estimate, reference, max_time_difference_s);
    matched.matched_by = "time";
  } else {
    throw std::runtime_error("cannot match " + estimate_path + " with " + reference_path +
                             ": one has names only, the other times only (pass the dataset's "
                             "timestamps.txt)");
  }
  for (size_t k = 0; k < match.size(); ++k) {
    if (match[k] < 0) continue;
    matched.names.push_back(reference.names.empty() ? TimeName(reference.times[k])
                                                    : reference.names[k]);
    matched.reference.push_back(ToIsometry(reference.world_from_sensor[k]));
    matched.estimate.push_back(ToIsometry(estimate.world_from_sensor[match[k]]));
  }
  matched.num_reference_unmatched = reference.Size() - matched.names.size();
  matched.num_estimate_unmatched = estimate.Size() - matched.names.size();
  if (matched.names.size() < 2) {
    throw std::runtime_error(std::to_string(matched.names.size()) + " frames of " + estimate_path +
                             " match frames of " + reference_path + " (by " + matched.matched_by +
                             "); at least 2 are needed");
  }
  return matched;
}

void WriteTrajectoryEvaluation(const std::string& output_path,
                               const MatchedTrajectories& matched,
                               const TrajectoryError& error,
                               const TrajectoryErrorOptions& options) {
  PartialOutputFolder partial(output_path);
  nlohmann::json metrics = ErrorJson(error);
  metrics["alignment"] = TrajectoryAlignmentName(options.alignment);
  metrics["matched_by"] = matched.matched_by;
  metrics["num_estimate_unmatched"] = matched.num_estimate_unmatched;
  metrics["num_reference_unmatched"] = matched.num_reference_unmatched;
  metrics["steps"] = StepsJson(matched, error);
  WriteFileAtomically(partial.File("metrics.json"), metrics.dump(2) + "\n");
  WritePlots(partial.Path(), matched, error);
  partial.Commit();
}

std::string TrajectoryErrorSummary(const TrajectoryError& error) {
  std::ostringstream line;
  line << std::fixed << std::setprecision(3);
  if (error.num_segments > 0) {
    line << "relative error " << error.translation_percent << " % / " << std::setprecision(5)
         << error.rotation_deg_per_m << " deg/m over " << error.num_segments << " segments";
  } else {
    line << "no relative error (the path is shorter than every segment length)";
  }
  line << std::setprecision(3) << "; end-to-end drift " << error.end_to_end_drift_percent
       << " % of " << std::setprecision(1) << error.path_length_m << " m; ATE RMSE "
       << std::setprecision(3) << error.position_rmse_m << " m";
  if (std::abs(error.alignment_scale - 1) > 1e-9)
    line << " (similarity scale " << std::setprecision(5) << error.alignment_scale << ")";
  return line.str();
}

}  // namespace colmap_lidar
