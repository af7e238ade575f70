// evaluate_depth_priors: the database's depth priors against the dataset's true depth maps.
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/depth_prior_evaluation.h"
#include "lidar/plot.h"
#include "lidar/util/atomic_file.h"

#include "colmap/controllers/option_manager.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <iomanip>
#include <iostream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

nlohmann::json StatisticsJson(const DepthPriorStatistics& statistics) {
  nlohmann::json json;
  json["num_priors"] = statistics.num_priors;
  json["median_abs_relative_error"] = statistics.median_abs_relative_error;
  json["mean_relative_error"] = statistics.mean_relative_error;
  json["mean_normalized_error"] = statistics.mean_normalized_error;
  json["within_1_sigma"] = statistics.within_1_sigma;
  json["within_2_sigma"] = statistics.within_2_sigma;
  json["within_3_sigma"] = statistics.within_3_sigma;
  json["beyond_10_sigma"] = statistics.beyond_10_sigma;
  return json;
}

void PrintStatistics(const std::string& label, const DepthPriorStatistics& statistics) {
  std::cout << std::fixed << std::setprecision(1) << "  " << label << ": " << statistics.num_priors
            << " priors, median |error| " << 100 * statistics.median_abs_relative_error
            << " % of the depth, mean error " << 100 * statistics.mean_relative_error << " % ("
            << std::setprecision(2) << statistics.mean_normalized_error
            << " sigma); within 1/2/3 sigma " << std::setprecision(1)
            << 100 * statistics.within_1_sigma << " / " << 100 * statistics.within_2_sigma << " / "
            << 100 * statistics.within_3_sigma
            << " % (Gaussian 68.3 / 95.4 / 99.7), beyond 10 sigma "
            << 100 * statistics.beyond_10_sigma << " %" << std::endl;
}

}  // namespace

int RunEvaluateDepthPriors(int argc, char** argv) {
  std::string database_path, dataset_path, output_path;
  DepthPriorEvaluationOptions options;
  colmap::OptionManager manager;
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

void RunEvaluateDepthPriorsStep(const std::string& database_path,
                                const std::string& dataset_path,
                                const std::string& output_path,
                                const DepthPriorEvaluationOptions& options) {
  const std::string truth_path = (fs::path(dataset_path) / "ground_truth" / "depth").string();
  const DepthPriorEvaluation evaluation = EvaluateDepthPriors(database_path, truth_path, options);
  std::cout << "evaluate_depth_priors: " << evaluation.errors.size() << " priors against "
            << truth_path << " (" << evaluation.num_without_true_depth
            << " on pixels without true depth, " << evaluation.images_without_truth.size()
            << " images without a true depth map)" << std::endl;
  PrintStatistics("all", evaluation.all);
  PrintStatistics("at depth edges", evaluation.at_edges);
  PrintStatistics("away from edges", evaluation.away_from_edges);
  PrintStatistics("within " + std::to_string(static_cast<int>(options.inlier_sigmas)) +
                      " sigma (what the adjuster's gate keeps)",
                  evaluation.inliers);

  fs::create_directories(output_path);
  nlohmann::json metrics;
  metrics["all"] = StatisticsJson(evaluation.all);
  metrics["at_edges"] = StatisticsJson(evaluation.at_edges);
  metrics["away_from_edges"] = StatisticsJson(evaluation.away_from_edges);
  metrics["inliers"] = StatisticsJson(evaluation.inliers);
  metrics["inlier_sigmas"] = options.inlier_sigmas;
  metrics["num_without_true_depth"] = evaluation.num_without_true_depth;
  metrics["images_without_truth"] = evaluation.images_without_truth;
  WriteFileAtomically((fs::path(output_path) / "metrics.json").string(), metrics.dump(2) + "\n");

  std::vector<double> normalized;
  for (const DepthPriorError& error : evaluation.errors) {
    normalized.push_back(std::abs(error.Normalized()));
  }
  HistogramPlotOptions plot;
  plot.title = "Depth prior error in units of its sigma";
  plot.x_label = "|prior - true| / sigma_d";
  plot.max_value = 6;
  WriteHistogramPng(
      (fs::path(output_path) / "normalized_error_histogram.png").string(), normalized, plot);
  std::cout << "evaluate_depth_priors: wrote " << output_path
            << "/{metrics.json, normalized_error_histogram.png}" << std::endl;
}

}  // namespace colmap_lidar
