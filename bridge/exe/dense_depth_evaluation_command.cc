// evaluate_dense_depth: a dense workspace's depth maps against the dataset's true depth maps.
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "colmap_ext/dense_depth_evaluation.h"
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

nlohmann::json StatisticsJson(const DenseDepthStatistics& s) {
  return {{"num_pixels", s.num_pixels},
          {"num_with_depth", s.num_with_depth},
          {"num_compared", s.num_compared},
          {"coverage", s.coverage},
          {"mean_error_m", s.mean_error_m},
          {"median_abs_error_m", s.median_abs_error_m},
          {"p90_abs_error_m", s.p90_abs_error_m},
          {"p99_abs_error_m", s.p99_abs_error_m},
          {"median_abs_relative_error", s.median_abs_relative_error},
          {"within_1cm", s.within_1cm},
          {"within_5cm", s.within_5cm}};
}

}  // namespace

int RunEvaluateDenseDepth(int argc, char** argv) {
  std::string dense_path, dataset_path, output_path;
  colmap::OptionManager manager;
  manager.AddRequiredOption(
      "dense_path", &dense_path, "densifier's output (COLMAP dense workspace)");
  manager.AddRequiredOption("dataset_path", &dataset_path, "dataset with ground_truth/depth/");
  manager.AddRequiredOption("output_path", &output_path, "directory for metrics.json and plots");
  manager.Parse(argc, argv);
  RunEvaluateDenseDepthStep(dense_path, dataset_path, output_path);
  return EXIT_SUCCESS;
}

void RunEvaluateDenseDepthStep(const std::string& dense_path,
                               const std::string& dataset_path,
                               const std::string& output_path) {
  const std::string truth_path = (fs::path(dataset_path) / "ground_truth" / "depth").string();
  const DenseDepthEvaluation evaluation = EvaluateDenseDepth(dense_path, truth_path);
  const DenseDepthStatistics& all = evaluation.all;
  std::cout << std::fixed << std::setprecision(1)
            << "evaluate_dense_depth: " << evaluation.image_names.size() << " depth maps against "
            << truth_path << " (" << evaluation.images_without_truth.size()
            << " without a true one, " << evaluation.images_of_another_size.size()
            << " of another size, not compared): depth on " << 100 * all.coverage
            << " % of the pixels; error median " << 1000 * all.median_abs_error_m << " mm, 90 % "
            << 1000 * all.p90_abs_error_m << " mm, 99 % " << 1000 * all.p99_abs_error_m
            << " mm, mean (bias) " << 1000 * all.mean_error_m << " mm; within 1 / 5 cm "
            << 100 * all.within_1cm << " / " << 100 * all.within_5cm << " %" << std::endl;

  PartialOutputFolder partial(output_path);
  nlohmann::json metrics;
  metrics["all"] = StatisticsJson(all);
  nlohmann::json per_image = nlohmann::json::object();
  for (size_t k = 0; k < evaluation.image_names.size(); ++k) {
    per_image[evaluation.image_names[k]] = StatisticsJson(evaluation.per_image[k]);
  }
  metrics["per_image"] = per_image;
  metrics["images_without_truth"] = evaluation.images_without_truth;
  metrics["images_of_another_size"] = evaluation.images_of_another_size;
  WriteFileAtomically(partial.File("metrics.json"), metrics.dump(2) + "\n");
  HistogramPlotOptions plot;
  plot.title = "Dense depth error against the true depth";
  plot.x_label = "|dense - true| [mm]";
  plot.value_scale = 1000;
  WriteHistogramPng(partial.File("error_histogram.png"), evaluation.abs_error_sample, plot);
  partial.Commit();
  std::cout << "evaluate_dense_depth: wrote " << output_path
            << "/{metrics.json, error_histogram.png}" << std::endl;
}

}  // namespace colmap_lidar
