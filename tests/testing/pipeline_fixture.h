// The default pipeline workspace shared by the pipeline tests: PipelineTest.DefaultScene... builds it
// (a CTest fixture setup, tests/CMakeLists.txt) and the dense-model and COLMAP-workflow tests read it,
// each writing into folders of its own, so that they run in parallel after it.
#pragma once

#include "bridge/simulation/simulate_dataset.h"
#include "tests/testing/run_command.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <string>

namespace colmap_lidar {
namespace testing {

inline const std::string kCli = COLMAP_LIDAR_CLI_EXE;
inline const std::string kColmap = COLMAP_LIDAR_COLMAP_EXE;

// The fixture: 8 stations of t_specimen, 300 k LiDAR points, no cam_from_lidar guess; the dataset in
// ROOT/dataset, the pipeline's workspace in ROOT/ws.
struct PipelineFixture {
  std::string root = std::string(COLMAP_LIDAR_TEST_FIXTURES) + "/pipeline_default";
  std::string dataset = root + "/dataset";
  std::string ws = root + "/ws";
  std::string File(const std::string& name) const { return ws + "/" + name; }
};

inline nlohmann::json ReadJson(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot read " + path);
  return nlohmann::json::parse(file);
}

inline std::string Simulate(const std::string& output_path,
                            const std::string& scene,
                            int num_stations,
                            double image_scale,
                            size_t lidar_points,
                            bool write_guess,
                            bool mono = false) {
  sim::SimulationOptions options;
  options.mono = mono;
  options.output_path = output_path;
  options.scene = scene;
  options.num_stations = num_stations;
  options.image_scale = image_scale;
  options.lidar_points = lidar_points;
  options.write_guess = write_guess;
  sim::SimulateDataset(options);
  return options.output_path;
}

// evaluate_model on a dense cloud of the model whose alignment evaluate_calibration wrote.
inline nlohmann::json EvaluateCloud(const std::string& cloud,
                                    const std::string& dataset,
                                    const std::string& truth_from_model,
                                    const std::string& output) {
  RunStep(kCli + " evaluate_model --model_path " + cloud + " --ground_truth_path " + dataset +
          "/ground_truth/surface.ply --truth_from_model " + truth_from_model + " --output_path " +
          output);
  return ReadJson(output + "/metrics.json");
}

inline void PrintCloudMetrics(const std::string& name, const nlohmann::json& m) {
  std::cout << std::fixed << std::setprecision(2) << "  " << std::left << std::setw(34) << name
            << " mean " << 1000 * m["mean_m"].get<double>() << " mm, median "
            << 1000 * m["median_m"].get<double>() << " mm, completeness 2/5/10 mm "
            << m["completeness_2mm"].get<double>() << "/" << m["completeness_5mm"].get<double>()
            << "/" << m["completeness_10mm"].get<double>() << ", density "
            << m["density_points_per_cm2"].get<double>() << " points/cm^2" << std::endl;
}

}  // namespace testing
}  // namespace colmap_lidar
