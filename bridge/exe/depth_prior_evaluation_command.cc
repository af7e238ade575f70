// evaluate_depth_priors: the database's depth priors against the dataset's true depth maps.
#include "bridge/exe/command_options.h"
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/depth_prior_evaluation.h"

namespace colmap_lidar {

int RunEvaluateDepthPriors(int argc, char** argv) {
  std::string database_path, dataset_path, output_path;
  DepthPriorEvaluationOptions options;
  CommandOptions manager;
  manager.AddRequiredOption("database_path", &database_path, "database with depth priors");
  manager.AddRequiredOption("dataset_path", &dataset_path, "dataset with ground_truth/depth/");
  manager.AddRequiredOption("output_path", &output_path, "directory for metrics.json and plots");
  manager.AddDefaultOption("edge_radius_px", &options.edge_radius_px);
  manager.AddDefaultOption("edge_relative_jump", &options.edge_relative_jump);
  manager.AddDefaultOption("inlier_sigmas", &options.inlier_sigmas);
  manager.Parse(argc, argv);
  RunEvaluateDepthPriorsStep(database_path, dataset_path, output_path, options);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
