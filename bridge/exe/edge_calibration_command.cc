// colmap-lidar calibrate_edges: cam_from_lidar by the edge-based method of Levinson & Thrun (RSS 2013),
// the baseline the joint optimisation is compared with (bridge/baselines/edge_calibration.h).
//   OUTPUT/cam_from_lidar.txt   qw qx qy qz tx ty tz (quaternion w first)
//   OUTPUT/report.json          J at the start and end, F_c, moves per level, time, the options
//   OUTPUT/edges_<station>.png  one station's edge transform, discontinuities before (red), after (green)
// With --profile_axis, no grid search: J along the rotation about that camera axis through the start
// (bridge/baselines/edge_axis_profile.h), the result turned to its peak, and OUTPUT/profile.png.
#include "bridge/baselines/edge_axis_profile.h"
#include "bridge/baselines/edge_calibration.h"
#include "bridge/evaluation/calibration_evaluation.h"
#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "lidar/plot.h"
#include "lidar/util/atomic_file.h"
#include "lidar/util/parallel_for_each.h"

#include "colmap/scene/reconstruction.h"
#include "colmap/util/misc.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <set>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// The stations to sum: all, or those whose left image SPARSE registered.
std::vector<size_t> SelectedStations(const StationDataset& dataset, const std::string& input_path) {
  std::vector<size_t> selected;
  std::set<std::string> registered;
  if (!input_path.empty()) {
    THROW_CHECK(fs::is_directory(input_path)) << "No sparse model at " << input_path;
    colmap::Reconstruction reconstruction;
    reconstruction.Read(input_path);
    for (const colmap::image_t image_id : reconstruction.RegImageIds()) {
      registered.insert(reconstruction.Image(image_id).Name());
    }
  }
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    if (input_path.empty() || registered.count(dataset.LeftImageName(i))) selected.push_back(i);
  }
  THROW_CHECK(!selected.empty()) << "no station of " << dataset.root << " is registered in "
                                 << input_path;
  return selected;
}

std::vector<EdgeStation> PrepareStations(const StationDataset& dataset,
                                         const std::vector<size_t>& selected,
                                         const EdgeCalibrationOptions& options) {
  std::vector<EdgeStation> stations(selected.size());
  ParallelForEach(static_cast<int>(selected.size()), [&](int k) {
    const size_t i = selected[k];
    const cv::Mat image = cv::imread(dataset.LeftImagePath(i), cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw std::runtime_error("cannot read " + dataset.LeftImagePath(i));
    const PointCloud cloud = ReadStationCloud(dataset.cloud_paths[i]);
    stations[k] =
        PrepareEdgeStation(dataset.stations[i], image, dataset.rig.left, cloud.points, options);
  });
  return stations;
}

colmap::Rigid3d InitialEstimate(const StationDataset& dataset, const std::string& path) {
  if (!path.empty()) return ReadPoseFile(path);
  if (dataset.rig.cam_from_lidar_guess) return *dataset.rig.cam_from_lidar_guess;
  throw std::invalid_argument(
      "calibrate_edges needs a starting cam_from_lidar: --cam_from_lidar FILE or "
      "\"cam_from_lidar_guess\" in " +
      (fs::path(dataset.root) / "rig.json").string());
}

nlohmann::json EdgeReport(const EdgeCalibrationResult& result,
                          const std::vector<EdgeStation>& stations,
                          const EdgeCalibrationOptions& options) {
  size_t num_points = 0;
  for (const EdgeStation& station : stations) num_points += station.discontinuities.size();
  return {{"objective_initial", result.initial_objective},
          {"objective_final", result.final_objective},
          {"fraction_lower_F_c", result.fraction_lower},
          {"converged", result.converged},
          {"moves_per_level", result.moves},
          {"objective_history", result.objective_history},
          {"rotation_steps_deg", options.rotation_steps_deg},
          {"translation_steps_m", options.translation_steps_m},
          {"num_stations", stations.size()},
          {"num_discontinuity_points", num_points},
          {"seconds", result.seconds}};
}

void PrintAgainstReference(const StationDataset& dataset, const colmap::Rigid3d& cam_from_lidar) {
  if (!dataset.HasReferenceExtrinsic()) return;
  const colmap::Rigid3d truth = ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  std::cout << "calibrate_edges: against ground_truth/cam_from_lidar.txt: rotation "
            << RotationErrorDeg(cam_from_lidar, truth) << " deg, translation "
            << (cam_from_lidar.translation - truth.translation).norm() * 1000 << " mm" << std::endl;
}

// The profile about `axis_in_cam` through `initial`: its report and plot into `partial`, the start
// turned to the peak returned.
colmap::Rigid3d ProfileStep(const std::vector<EdgeStation>& stations,
                            const colmap::Rigid3d& initial,
                            const Eigen::Vector3d& axis_in_cam,
                            const EdgeAxisProfileOptions& options,
                            PartialOutputFolder* partial) {
  const EdgeAxisProfile profile = ProfileEdgeObjective(stations, initial, axis_in_cam, options);
  std::cout << std::setprecision(4) << "calibrate_edges: J about camera axis ("
            << profile.axis_in_cam.transpose() << ") peaks at " << profile.peak_deg
            << " deg, bootstrap sigma " << profile.sigma_deg << " deg"
            << (profile.at_range_end ? " (at the end of the range: widen --profile_half_range_deg)"
                                     : "")
            << std::endl;
  const nlohmann::json report = {{"axis_in_cam", profile.axis_in_cam},
                                 {"angles_deg", profile.angles_deg},
                                 {"objective", profile.objective},
                                 {"peak_deg", profile.peak_deg},
                                 {"sigma_deg", profile.sigma_deg},
                                 {"at_range_end", profile.at_range_end},
                                 {"num_stations", stations.size()}};
  WriteFileAtomically(partial->File("report.json"), report.dump(2) + "\n");
  LinePlotOptions plot;
  plot.title = "Edge objective about one camera axis";
  plot.x_label = "angle from the start [deg]";
  plot.y_label = "J";
  WriteLinePlotPng(
      partial->File("profile.png"), {{"J", profile.angles_deg, profile.objective}}, plot);
  return TurnAboutCameraAxis(initial, profile.axis_in_cam, profile.peak_deg);
}

colmap::Rigid3d GridStep(const std::vector<EdgeStation>& stations,
                         const colmap::Rigid3d& initial,
                         const EdgeCalibrationOptions& options,
                         PartialOutputFolder* partial) {
  const EdgeCalibrationResult result = CalibrateFromEdges(stations, initial, options);
  std::cout << std::setprecision(4) << "calibrate_edges: J " << result.initial_objective << " -> "
            << result.final_objective << ", F_c " << result.fraction_lower << ", "
            << result.objective_history.size() - 1 << " moves, " << result.seconds << " s"
            << (result.converged ? "" : " (a level stopped at max_moves_per_level)") << std::endl;
  WriteFileAtomically(partial->File("report.json"),
                      EdgeReport(result, stations, options).dump(2) + "\n");
  return result.cam_from_lidar;
}

}  // namespace

void RunCalibrateEdgesStep(const EdgeCalibrationPaths& paths,
                           const EdgeCalibrationOptions& options,
                           const std::optional<EdgeAxisProfileRequest>& profile) {
  const std::string& dataset_path = paths.dataset_path;
  const std::string& input_path = paths.input_path;
  const std::string& cam_from_lidar_path = paths.cam_from_lidar_path;
  const std::string& output_path = paths.output_path;
  const std::string& registration_path = paths.registration_path;
  THROW_CHECK(options.Check());
  if (profile) THROW_CHECK(profile->options.Check());
  const StationDataset dataset =
      registration_path.empty()
          ? ReadStationDataset(dataset_path)
          : WithRegistratorClouds(ReadStationDataset(dataset_path), registration_path);
  const colmap::Rigid3d initial = InitialEstimate(dataset, cam_from_lidar_path);
  const std::vector<size_t> selected = SelectedStations(dataset, input_path);
  std::cout << "calibrate_edges: " << selected.size() << " stations: image edges and LiDAR depth "
            << "discontinuities" << std::endl;
  const std::vector<EdgeStation> stations = PrepareStations(dataset, selected, options);
  PartialOutputFolder partial(output_path);
  const colmap::Rigid3d result =
      profile ? ProfileStep(stations, initial, profile->axis_in_cam, profile->options, &partial)
              : GridStep(stations, initial, options, &partial);
  PrintAgainstReference(dataset, result);
  WritePoseFile(partial.File("cam_from_lidar.txt"),
                "cam_from_lidar by calibrate_edges (Levinson & Thrun 2013)",
                result);
  const EdgeStation& shown = stations[stations.size() / 2];
  cv::imwrite(partial.File("edges_" + shown.name + ".png"),
              EdgeOverlay(shown, initial, result, options.min_depth_m));
  partial.Commit();
}

int RunCalibrateEdges(int argc, char** argv) {
  std::string dataset_path, input_path, cam_from_lidar_path, output_path, registration_path;
  std::string rotation_steps = "1,0.5,0.2,0.1", translation_steps = "0.05,0.03,0.02,0.01";
  EdgeCalibrationOptions options;
  DepthDiscontinuityOptions& lidar = options.discontinuities;
  int max_points = static_cast<int>(lidar.max_points);
  CommandOptions manager;
  manager.AddRequiredOption("dataset_path", &dataset_path);
  manager.AddRequiredOption("output_path", &output_path);
  manager.AddDefaultOption("input_path", &input_path, "sparse model: only its stations are summed");
  manager.AddDefaultOption("cam_from_lidar",
                           &cam_from_lidar_path,
                           "start (qw qx qy qz tx ty tz); default rig.json's guess");
  manager.AddDefaultOption("registration_path",
                           &registration_path,
                           "lidar_registrator's output: its static (de-skewed) clouds instead of "
                           "the dataset's (a moving platform's sweeps)");
  manager.AddDefaultOption("rotation_steps_deg", &rotation_steps, "grid steps, coarse to fine");
  manager.AddDefaultOption("translation_steps_m", &translation_steps, "one per rotation step");
  manager.AddDefaultOption("max_moves_per_level", &options.max_moves_per_level);
  manager.AddDefaultOption("angular_resolution_deg", &lidar.angular_resolution_deg, "0: automatic");
  manager.AddDefaultOption("min_score", &lidar.min_score, "X = step^gamma, m^gamma");
  manager.AddDefaultOption("max_points_per_station", &max_points, "strongest discontinuities");
  manager.AddDefaultOption("blur_sigma_px", &options.transform.blur_sigma_px);
  manager.AddDefaultOption("alpha", &options.transform.alpha);
  manager.AddDefaultOption("gamma", &options.transform.gamma, "decay per pixel of the transform");
  std::string profile_axis;
  EdgeAxisProfileOptions profile_options;
  manager.AddDefaultOption("profile_axis",
                           &profile_axis,
                           "x,y,z in the camera frame: J along the rotation about it instead of "
                           "the grid search");
  manager.AddDefaultOption("profile_half_range_deg", &profile_options.half_range_deg);
  manager.AddDefaultOption("profile_step_deg", &profile_options.step_deg);
  manager.Parse(argc, argv);
  std::optional<EdgeAxisProfileRequest> profile;
  if (!profile_axis.empty()) {
    const std::vector<double> axis = colmap::CSVToVector<double>(profile_axis);
    const Eigen::Vector3d axis_in_cam =
        axis.size() == 3 ? Eigen::Vector3d(axis[0], axis[1], axis[2]) : Eigen::Vector3d::Zero();
    if (!axis_in_cam.allFinite() || !(axis_in_cam.norm() > 0)) {
      throw std::invalid_argument("--profile_axis needs x,y,z (finite, not all 0): " +
                                  profile_axis);
    }
    profile_options.min_depth_m = options.min_depth_m;
    profile = EdgeAxisProfileRequest{axis_in_cam, profile_options};
  }
  options.rotation_steps_deg = colmap::CSVToVector<double>(rotation_steps);
  options.translation_steps_m = colmap::CSVToVector<double>(translation_steps);
  THROW_CHECK_GE(max_points, 0);
  lidar.max_points = static_cast<size_t>(max_points);
  RunCalibrateEdgesStep(
      {dataset_path, input_path, cam_from_lidar_path, output_path, registration_path},
      options,
      profile);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
