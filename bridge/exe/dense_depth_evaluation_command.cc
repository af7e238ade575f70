// evaluate_dense_depth: a dense workspace's depth maps against the dataset's true depth maps.
#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/dense_depth_evaluation.h"

namespace colmap_lidar {

int RunEvaluateDenseDepth(int argc, char** argv) {
  std::string dense_path, dataset_path, output_path;
  CommandOptions manager;
  manager.AddRequiredOption(
      "dense_path", &dense_path, "densifier's output (COLMAP dense workspace)");
  manager.AddRequiredOption("dataset_path", &dataset_path, "dataset with ground_truth/depth/");
  manager.AddRequiredOption("output_path", &output_path, "directory for metrics.json and plots");
  manager.Parse(argc, argv);
  RunEvaluateDenseDepthStep(dense_path, dataset_path, output_path);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
