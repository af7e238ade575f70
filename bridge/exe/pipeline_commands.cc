// pose_initializer and pipeline: from raw stations to a metric sparse model with cam_from_lidar.
#include "bridge/exe/commands.h"
#include "bridge/pose_initializer.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"

#include "colmap/controllers/option_manager.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <vector>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

int RunWithArguments(int (*command)(int, char**), const std::vector<std::string>& arguments) {
  std::vector<std::string> storage = arguments;
  std::vector<char*> argv;
  for (std::string& argument : storage) argv.push_back(argument.data());
  argv.push_back(nullptr);
  return command(static_cast<int>(storage.size()), argv.data());
}

}  // namespace

int RunPoseInitializer(int argc, char** argv) {
  std::string dataset_path, registration_path, output_path, input_path;
  PoseInitializerOptions initializer;
  colmap::OptionManager options;
  options.AddDatabaseOptions();
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddDefaultOption("registration_path",
                           &registration_path,
                           "lidar_registrator's output (pairs.txt); empty: no "
                           "LiDAR edges");
  options.AddRequiredOption("output_path", &output_path);
  options.AddDefaultOption("input_path",
                           &input_path,
                           "an existing COLMAP model of the same database (e.g. "
                           "colmap mapper's): rescaled to metres instead of "
                           "initialising poses");
  options.AddDefaultOption("use_guess",
                           &initializer.use_guess,
                           "use rig.json's cam_from_lidar_guess if present "
                           "(0: hand-eye)");
  options.AddDefaultOption("min_pair_inliers", &initializer.image_pairs.min_inliers);
  options.Parse(argc, argv);
  const auto start = std::chrono::steady_clock::now();
  const StationDataset dataset = ReadStationDataset(dataset_path);
  PartialOutputFolder partial(output_path);
  PoseInitialization init;
  double scale = 1;
  if (input_path.empty()) {
    init = InitializePoses(*options.database_path, dataset, registration_path, initializer);
    std::cout << "Pose graph: " << init.num_image_edges << " image edges (A_c), "
              << init.num_lidar_edges << " LiDAR edges (A_l); " << init.cam_from_world.size()
              << " stations reachable" << std::endl;
    TriangulateInitialModel(
        *options.database_path, (fs::path(dataset.root) / "images").string(), init, partial.Path());
  } else {
    THROW_CHECK(fs::is_directory(input_path)) << "no sparse model folder " << input_path;
    colmap::Reconstruction model;
    model.Read(input_path);
    init = InitializeFromModel(
        *options.database_path, dataset, registration_path, initializer, &model, &scale);
    std::cout << "Rescaled " << input_path << " to metres by " << scale
              << " (median of depth prior / model depth); " << model.NumRegImages()
              << " registered images" << std::endl;
    model.WriteBinary(partial.Path());
  }
  std::cout << "cam_from_lidar: " << init.extrinsic_source
            << "; hand-eye: " << init.hand_eye.message << std::endl;
  for (const std::string& name : init.unreachable) {
    std::cout << "WARNING: station image " << name
              << " is not in the model (no image or LiDAR edge reaches it)" << std::endl;
  }
  WritePoseFile(partial.File("cam_from_lidar.txt"),
                "initial cam_from_lidar (" + init.extrinsic_source + "); qw qx qy qz tx ty tz",
                init.cam_from_lidar);
  nlohmann::json report;
  report["extrinsic_source"] = init.extrinsic_source;
  report["hand_eye"] = {{"unique", init.hand_eye.unique},
                        {"message", init.hand_eye.message},
                        {"motions", init.hand_eye.num_motions},
                        {"max_axis_angle_deg", init.hand_eye.max_axis_angle_deg}};
  report["image_edges"] = init.num_image_edges;
  report["lidar_edges"] = init.num_lidar_edges;
  report["stations"] = init.cam_from_world.size();
  report["unreachable"] = init.unreachable;
  report["input_model"] = input_path;
  report["scale_to_metres"] = scale;
  WriteFileAtomically(partial.File("initialization.json"), report.dump(2) + "\n");
  partial.Commit();
  std::cout << "Wrote the initial model to " << output_path << " (" << std::fixed
            << std::setprecision(1)
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s)" << std::endl;
  return EXIT_SUCCESS;
}

int RunPipeline(int argc, char** argv) {
  std::string dataset_path, workspace_path;
  bool overwrite = false;
  bool use_guess = true;
  std::string mode = "joint";
  colmap::OptionManager options;
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddRequiredOption("workspace_path", &workspace_path);
  options.AddDefaultOption("overwrite", &overwrite, "rerun finished steps");
  options.AddDefaultOption("use_guess",
                           &use_guess,
                           "0: initialise cam_from_lidar by hand-eye even if "
                           "rig.json has a guess");
  options.AddDefaultOption("mode", &mode, "joint | precalibrated | stereo_only");
  options.Parse(argc, argv);
  const StationDataset dataset = ReadStationDataset(dataset_path);
  const fs::path ws(workspace_path);
  fs::create_directories(ws / "steps");
  const std::string database = (ws / "database.db").string();
  const std::string stereo = (ws / "stereo").string();
  const std::string lidar = (ws / "lidar").string();
  const std::string initial = (ws / "sparse" / "initial").string();
  const std::string joint = (ws / "sparse" / "joint").string();
  const std::string dense = (ws / "dense").string();
  fs::create_directories(ws / "sparse");

  struct Step {
    std::string name;
    int (*command)(int, char**);
    std::vector<std::string> arguments;
  };
  std::vector<Step> steps = {
      {"import_dataset",
       &RunImportDataset,
       {"--dataset_path", dataset.root, "--database_path", database}},
      {"stereo_depth", &RunStereoDepth, {"--dataset_path", dataset.root, "--output_path", stereo}},
      {"depth_prior_extractor",
       &RunDepthPriorExtractor,
       {"--database_path", database, "--depth_path", stereo}},
      {"lidar_registrator",
       &RunLidarRegistrator,
       {"--lidar_path",
        (fs::path(dataset.root) / "lidar").string(),
        "--output_path",
        lidar,
        "--max_neighbors",
        "4"}},
      {"pose_initializer",
       &RunPoseInitializer,
       {"--database_path",
        database,
        "--dataset_path",
        dataset.root,
        "--registration_path",
        lidar,
        "--output_path",
        initial,
        "--use_guess",
        use_guess ? "1" : "0"}},
      {"joint_adjuster",
       &RunJointAdjuster,
       {"--database_path",
        database,
        "--input_path",
        initial,
        "--dataset_path",
        dataset.root,
        "--output_path",
        joint,
        "--mode",
        mode}},
      {"densifier",
       &RunDensifier,
       {"--input_path",
        joint,
        "--dataset_path",
        dataset.root,
        "--depth_path",
        stereo,
        "--output_path",
        dense,
        "--refine_with_lidar",
        mode == "stereo_only" ? "0" : "1"}},
  };
  if (dataset.HasGroundTruth()) {
    const std::string evaluation = (ws / "evaluation").string();
    steps.push_back(
        {"evaluate_calibration",
         &RunEvaluateCalibration,
         {"--dataset_path", dataset.root, "--input_path", joint, "--output_path", evaluation}});
    steps.push_back({"evaluate_model",
                     &RunEvaluateModel,
                     {"--model_path",
                      (fs::path(dense) / "fused.ply").string(),
                      "--ground_truth_path",
                      dataset.GroundTruthPath("surface.ply"),
                      "--truth_from_model",
                      (fs::path(evaluation) / "truth_from_model.txt").string(),
                      "--output_path",
                      (fs::path(evaluation) / "model").string()}});
  }
  std::vector<std::tuple<std::string, std::string, double>> table;
  for (size_t k = 0; k < steps.size(); ++k) {
    const Step& step = steps[k];
    const fs::path marker = ws / "steps" / (step.name + ".done");
    if (fs::exists(marker) && !overwrite) {
      std::cout << "== [" << k + 1 << "/" << steps.size() << "] " << step.name
                << ": done before, skipped (--overwrite 1 reruns it)" << std::endl;
      table.emplace_back(step.name, "skipped", 0.0);
      continue;
    }
    std::cout << "== [" << k + 1 << "/" << steps.size() << "] " << step.name << std::endl;
    fs::remove(marker);
    if (step.name == "import_dataset" && overwrite) fs::remove(database);
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::string> arguments = {step.name};
    arguments.insert(arguments.end(), step.arguments.begin(), step.arguments.end());
    const int status = RunWithArguments(step.command, arguments);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (status != EXIT_SUCCESS) {
      throw std::runtime_error("step " + step.name + " failed");
    }
    WriteFileAtomically(marker.string(), step.name + " finished\n");
    table.emplace_back(step.name, "ran", seconds);
  }
  std::cout << "\n== Pipeline summary (" << workspace_path << ")\n";
  for (const auto& [name, status, seconds] : table) {
    std::cout << "  " << std::left << std::setw(24) << name << std::setw(9) << status << std::right
              << std::fixed << std::setprecision(1) << std::setw(8) << seconds << " s\n";
  }
  std::cout << "  model: " << joint << " (cam_from_lidar.txt, report.json)\n"
            << "  dense: " << dense << " (fused.ply, lidar_map.ply, COLMAP dense workspace)"
            << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
