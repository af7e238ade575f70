// Cost of the joint problem against COLMAP's plain bundle adjustment on the same reconstruction: COLMAP's
// BundleAdjuster::Solve (set-up + N iterations) vs the joint adjuster's solve (COLMAP's set-up, our
// depth-prior and LiDAR blocks, N iterations), N = 1 and 10. Prints a Markdown table.
//   joint_adjuster_benchmark DATASET DATABASE WORK_DIR
// DATABASE must hold the dataset's images, matches and depth priors (import_dataset,
// depth_prior_extractor). The initial model is the true poses with landmarks from `colmap
// point_triangulator`; cam_from_lidar starts at the truth.
#include "bridge/joint/joint_adjuster.h"
#include "bridge/joint/joint_problem_data.h"
#include "colmap_ext/station_dataset.h"

#include "colmap/estimators/bundle_adjustment.h"
#include "colmap/feature/utils.h"
#include "colmap/scene/database.h"
#include "colmap/scene/reconstruction.h"

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

double Seconds(const std::chrono::steady_clock::time_point& start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string TriangulatedTrueModel(const StationDataset& dataset,
                                  const std::string& database_path,
                                  const std::string& work) {
  const auto truth = ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt"));
  colmap::Reconstruction reconstruction;
  const colmap::Database database(database_path);
  for (const colmap::Camera& camera : database.ReadAllCameras()) {
    reconstruction.AddCamera(camera);
  }
  for (colmap::Image image : database.ReadAllImages()) {
    image.CamFromWorld() = truth.at(fs::path(image.Name()).stem().string());
    image.SetPoints2D(
        colmap::FeatureKeypointsToPointsVector(database.ReadKeypoints(image.ImageId())));
    reconstruction.AddImage(image);
    reconstruction.RegisterImage(image.ImageId());
  }
  fs::create_directories(work + "/initial");
  fs::create_directories(work + "/triangulated");
  reconstruction.Write(work + "/initial");
  const std::string command =
      std::string(COLMAP_LIDAR_COLMAP_EXE) + " point_triangulator --database_path " +
      database_path + " --image_path " + dataset.root + "/images --input_path " + work +
      "/initial --output_path " + work + "/triangulated > " + work + "/triangulator.log 2>&1";
  if (std::system(command.c_str()) != 0) {
    throw std::runtime_error("colmap point_triangulator failed: " + command);
  }
  return work + "/triangulated";
}

struct Timing {
  double seconds = 0;
  int iterations = 0;
  double seconds_per_iteration = 0;  // Ceres' own iteration times
  size_t residual_blocks = 0;
  size_t residuals = 0;
};

Timing PlainBundleAdjustment(colmap::Reconstruction reconstruction, int iterations) {
  colmap::BundleAdjustmentOptions options;
  options.refine_focal_length = false;
  options.refine_principal_point = false;
  options.refine_extra_params = false;
  options.print_summary = false;
  options.solver_options.max_num_iterations = iterations;
  colmap::BundleAdjustmentConfig config;
  std::vector<colmap::image_t> ids = reconstruction.RegImageIds();
  std::sort(ids.begin(), ids.end());
  for (const colmap::image_t id : ids) config.AddImage(id);
  config.SetConstantCamPose(ids.front());
  colmap::BundleAdjuster adjuster(options, config);
  const auto start = std::chrono::steady_clock::now();
  adjuster.Solve(&reconstruction);
  Timing timing;
  timing.seconds = Seconds(start);
  timing.iterations = static_cast<int>(adjuster.Summary().iterations.size()) - 1;
  timing.seconds_per_iteration = MeanIterationSeconds(adjuster.Summary());
  timing.residual_blocks = adjuster.Summary().num_residual_blocks;
  timing.residuals = adjuster.Summary().num_residuals;
  return timing;
}

Timing JointSolve(colmap::Reconstruction reconstruction,
                  colmap::Rigid3d cam_from_lidar,
                  const JointProblemData& data,
                  int iterations) {
  JointAdjusterOptions options;
  options.num_association_rounds = 1;
  options.max_association_rounds = 1;
  options.max_outlier_iterations = 1;
  options.max_num_iterations = iterations;
  options.initial_association_distance_m = options.association.max_distance;
  const JointAdjuster adjuster(options);
  const JointAdjustmentSummary summary = adjuster.Run(data, &reconstruction, &cam_from_lidar);
  Timing timing;
  timing.seconds = summary.solves.front().seconds;
  timing.iterations = summary.solves.front().num_iterations - 1;
  timing.seconds_per_iteration = summary.solves.front().seconds_per_iteration;
  timing.residual_blocks = summary.solves.front().residual_blocks;
  timing.residuals = summary.solves.front().residuals;
  return timing;
}

}  // namespace
}  // namespace colmap_lidar

int main(int argc, char** argv) {
  using namespace colmap_lidar;
  if (argc != 4) {
    std::cerr << "usage: joint_adjuster_benchmark DATASET DATABASE WORK_DIR\n";
    return EXIT_FAILURE;
  }
  try {
    const StationDataset dataset = ReadStationDataset(argv[1]);
    const std::string model = TriangulatedTrueModel(dataset, argv[2], argv[3]);
    colmap::Reconstruction reconstruction;
    reconstruction.Read(model);
    const colmap::Rigid3d cam_from_lidar =
        ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
    const auto load_start = std::chrono::steady_clock::now();
    const std::unique_ptr<LoadedJointData> loaded = LoadJointProblemData(
        argv[2], dataset, reconstruction, cam_from_lidar, true, JointDataOptions());
    const double load_seconds = Seconds(load_start);

    std::ostringstream table;
    table
        << std::fixed << std::setprecision(4)
        << "| problem | iterations | residual blocks | residuals | solve time [s] | per iteration "
           "(Ceres) [s] |\n"
        << "|---|---|---|---|---|---|\n";
    for (const int iterations : {1, 10}) {
      const Timing plain = PlainBundleAdjustment(reconstruction, iterations);
      const Timing joint = JointSolve(reconstruction, cam_from_lidar, loaded->data, iterations);
      const auto row = [&](const std::string& name, const Timing& t) {
        table << "| " << name << " | " << t.iterations << " | " << t.residual_blocks << " | "
              << t.residuals << " | " << t.seconds << " | " << t.seconds_per_iteration << " |\n";
      };
      row("COLMAP BundleAdjuster::Solve", plain);
      row("joint (reprojection + depth + LiDAR + T_e)", joint);
      table << std::setprecision(2) << "| **ratio** (joint / COLMAP) | | | | **"
            << joint.seconds / plain.seconds << "** | **"
            << joint.seconds_per_iteration / plain.seconds_per_iteration << "** |\n"
            << std::setprecision(4);
    }
    std::cout << reconstruction.NumRegImages() << " images, " << reconstruction.NumPoints3D()
              << " landmarks; loading clouds, "
              << "depth priors and the pose graph (once): " << std::fixed << std::setprecision(1)
              << load_seconds << " s\n\n"
              << table.str();
  } catch (const std::exception& error) {
    std::cerr << "ERROR: " << error.what() << "\n";
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
