// colmap-lidar calibrate_edges: cam_from_lidar by the edge-based method of Levinson & Thrun (RSS 2013),
// the baseline the joint optimisation is compared with (bridge/edge_calibration.h).
//   OUTPUT/cam_from_lidar.txt   qw qx qy qz tx ty tz (quaternion w first)
//   OUTPUT/report.json          J at the start and end, F_c, moves per level, time, the options
//   OUTPUT/edges_<station>.png  one station's edge transform, discontinuities before (red), after (green)
#include "bridge/calibration_evaluation.h"
#include "bridge/edge_calibration.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/atomic_file.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "lidar/parallel_for_each.h"

#include "colmap/controllers/option_manager.h"
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

}  // namespace

void RunCalibrateEdgesStep(const std::string& dataset_path,
                           const std::string& input_path,
                           const std::string& cam_from_lidar_path,
                           const std::string& output_path,
                           const EdgeCalibrationOptions& options,
                           const std::string& registration_path) {
  THROW_CHECK(options.Check());
  const StationDataset dataset =
      registration_path.empty()
          ? ReadStationDataset(dataset_path)
          : WithRegistratorClouds(ReadStationDataset(dataset_path), registration_path);
  const colmap::Rigid3d initial = InitialEstimate(dataset, cam_from_lidar_path);
  const std::vector<size_t> selected = SelectedStations(dataset, input_path);
  std::cout << "calibrate_edges: " << selected.size() << " stations: image edges and LiDAR depth "
            << "discontinuities" << std::endl;
  const std::vector<EdgeStation> stations = PrepareStations(dataset, selected, options);
  const EdgeCalibrationResult result = CalibrateFromEdges(stations, initial, options);
  std::cout << std::setprecision(4) << "calibrate_edges: J " << result.initial_objective << " -> "
            << result.final_objective << ", F_c " << result.fraction_lower << ", "
            << result.objective_history.size() - 1 << " moves, " << result.seconds << " s"
            << (result.converged ? "" : " (a level stopped at max_moves_per_level)") << std::endl;
  if (dataset.HasReferenceExtrinsic()) {
    const colmap::Rigid3d truth = ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
    std::cout << "calibrate_edges: against ground_truth/cam_from_lidar.txt: rotation "
              << RotationErrorDeg(result.cam_from_lidar, truth) << " deg, translation "
              << (result.cam_from_lidar.translation - truth.translation).norm() * 1000 << " mm"
              << std::endl;
  }
  PartialOutputFolder partial(output_path);
  WritePoseFile(partial.File("cam_from_lidar.txt"),
                "cam_from_lidar by calibrate_edges (Levinson & Thrun 2013)",
                result.cam_from_lidar);
  WriteFileAtomically(partial.File("report.json"),
                      EdgeReport(result, stations, options).dump(2) + "\n");
  const EdgeStation& shown = stations[stations.size() / 2];
  cv::imwrite(partial.File("edges_" + shown.name + ".png"),
              EdgeOverlay(shown, initial, result.cam_from_lidar, options.min_depth_m));
  partial.Commit();
}

int RunCalibrateEdges(int argc, char** argv) {
  std::string dataset_path, input_path, cam_from_lidar_path, output_path, registration_path;
  std::string rotation_steps = "1,0.5,0.2,0.1", translation_steps = "0.05,0.03,0.02,0.01";
  EdgeCalibrationOptions options;
  DepthDiscontinuityOptions& lidar = options.discontinuities;
  int max_points = static_cast<int>(lidar.max_points);
  colmap::OptionManager manager;
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
  manager.Parse(argc, argv);
  options.rotation_steps_deg = colmap::CSVToVector<double>(rotation_steps);
  options.translation_steps_m = colmap::CSVToVector<double>(translation_steps);
  THROW_CHECK_GE(max_points, 0);
  lidar.max_points = static_cast<size_t>(max_points);
  RunCalibrateEdgesStep(
      dataset_path, input_path, cam_from_lidar_path, output_path, options, registration_path);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
