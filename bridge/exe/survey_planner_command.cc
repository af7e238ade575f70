// plan_survey: arguments, the printed table and the report files around bridge/survey/survey_planner.h.
// Files written (atomically, as one folder): report.json (quaternions w first), best_plan.txt (the
// plan's stations and the best candidate, "<name> qw qx qy qz tx ty tz" cam_from_world per line) and
// candidates.txt (every candidate, best first).
#include "bridge/exe/survey_planner_command.h"

#include "bridge/exe/command_options.h"
#include "bridge/survey/survey_planner.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "lidar/util/atomic_file.h"

#include <nlohmann/json.hpp>

#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

namespace colmap_lidar {
namespace {

std::string Sigmas(const sim::CalibrationPrediction& prediction) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(3) << "rotation " << prediction.rotation_sigma_deg.x()
       << " " << prediction.rotation_sigma_deg.y() << " " << prediction.rotation_sigma_deg.z()
       << " deg, translation " << std::setprecision(1) << prediction.translation_sigma_mm.x() << " "
       << prediction.translation_sigma_mm.y() << " " << prediction.translation_sigma_mm.z()
       << " mm (camera x y z)";
  return text.str();
}

nlohmann::json PoseJson(const colmap::Rigid3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation;
  return {{"rotation_wxyz", {q.w(), q.x(), q.y(), q.z()}},
          {"translation", {pose.translation.x(), pose.translation.y(), pose.translation.z()}}};
}

nlohmann::json PredictionJson(const sim::CalibrationPrediction& prediction) {
  const Eigen::Vector3d& r = prediction.rotation_sigma_deg;
  const Eigen::Vector3d& t = prediction.translation_sigma_mm;
  return {{"motion_unique", prediction.motion.unique},
          {"motion_verdict", prediction.motion.verdict},
          {"sigma_rotation_deg", {r.x(), r.y(), r.z()}},
          {"sigma_translation_mm", {t.x(), t.y(), t.z()}},
          {"worst_ratio_to_threshold", prediction.worst_ratio},
          {"worst_axis", prediction.worst_axis},
          {"unobservable", prediction.uncertainty.unobservable}};
}

void PrintPrediction(const std::string& title, const sim::CalibrationPrediction& prediction) {
  std::cout << title << ": " << Sigmas(prediction) << "; worst " << prediction.worst_axis << " at "
            << std::setprecision(3) << prediction.worst_ratio << "x its threshold" << std::endl;
  std::cout << "  motion: " << prediction.motion.verdict << std::endl;
  for (const std::string& sentence : prediction.uncertainty.unobservable) {
    std::cout << "  UNOBSERVABLE: " << sentence << std::endl;
  }
}

void WriteOutputs(const std::string& output_path,
                  const std::map<std::string, colmap::Rigid3d>& planned,
                  const sim::SurveyPlan& plan,
                  const nlohmann::json& settings) {
  nlohmann::json report = {{"settings", settings}, {"planned", PredictionJson(plan.planned)}};
  std::map<std::string, colmap::Rigid3d> candidates;
  for (size_t k = 0; k < plan.candidates.size(); ++k) {
    const sim::CandidateStation& c = plan.candidates[k];
    nlohmann::json entry = PredictionJson(c.prediction);
    entry["rank"] = k + 1;
    entry["description"] = c.description;
    entry["cam_from_world"] = PoseJson(c.cam_from_world);
    report["candidates"].push_back(entry);
    std::ostringstream name;
    name << "candidate_" << std::setw(2) << std::setfill('0') << k + 1;
    candidates[name.str()] = c.cam_from_world;
  }
  PartialOutputFolder partial(output_path);
  std::ofstream(partial.File("report.json")) << report.dump(2) << "\n";
  const std::string header =
      "cam_from_world of the left camera: name qw qx qy qz tx ty tz (quaternion w first)";
  WriteNamedPoses(
      partial.File("candidates.txt"), "plan_survey candidates, best first; " + header, candidates);
  if (!plan.candidates.empty()) {
    std::map<std::string, colmap::Rigid3d> best = planned;
    best["candidate_01"] = plan.candidates.front().cam_from_world;
    WriteNamedPoses(
        partial.File("best_plan.txt"), "the plan and its best extra station; " + header, best);
  }
  partial.Commit();
}

}  // namespace

int RunPlanSurvey(int argc, char** argv) {
  std::string scene_name = "t_specimen", surface_path, stations_path, output_path;
  sim::SurveyPlanOptions options;
  int lidar_points = static_cast<int>(options.lidar_points), seed = 1;
  CommandOptions manager;
  manager.AddDefaultOption(
      "scene", &scene_name, "t_specimen | square_pillar | cylinder_pillar | bridge_pier | street");
  manager.AddDefaultOption(
      "surface", &surface_path, "instead of --scene: the structure as points (.ply/.pcd, z up)");
  manager.AddRequiredOption(
      "stations", &stations_path, "planned stations: name qw qx qy qz tx ty tz (cam_from_world)");
  manager.AddRequiredOption("output_path", &output_path, "folder for report.json, best_plan.txt");
  manager.AddDefaultOption("num_candidate_positions",
                           &options.num_candidate_positions,
                           "positions on a ring around the structure, each level and tilted");
  manager.AddDefaultOption("candidate_tilt_deg", &options.candidate_tilt_deg);
  manager.AddDefaultOption("pixel_noise", &options.pixel_noise, "keypoint noise [px]");
  manager.AddDefaultOption("lidar_range_noise_m", &options.lidar_range_noise_m);
  manager.AddDefaultOption("lidar_points", &lidar_points, "LiDAR rays per simulated station");
  manager.AddDefaultOption("seed", &seed);
  manager.Parse(argc, argv);
  options.lidar_points = static_cast<size_t>(std::max(0, lidar_points));
  options.seed = static_cast<uint64_t>(seed);
  THROW_CHECK(options.Check());  // before any file is read
  // The scene (if any) outlives the target that refers to it.
  std::optional<sim::Scene> scene;
  if (surface_path.empty()) scene.emplace(sim::Scene::Create(scene_name));
  const sim::SurveyTarget target =
      scene
          ? sim::TargetOfScene(*scene)
          : sim::TargetOfSurface(std::make_shared<const PointCloud>(ReadPointCloud(surface_path)));
  const std::string structure = surface_path.empty() ? scene_name : surface_path;
  const std::map<std::string, colmap::Rigid3d> planned = ReadNamedPoses(stations_path);
  std::vector<colmap::Rigid3d> stations;
  for (const auto& [name, pose] : planned) stations.push_back(pose);
  if (stations.size() < 2) {
    throw std::invalid_argument(stations_path + " holds " + std::to_string(stations.size()) +
                                " station(s); a plan needs at least 2");
  }
  std::cout << "plan_survey: " << stations.size() << " planned stations of " << structure << ", "
            << 2 * options.num_candidate_positions << " candidates" << std::endl;
  const sim::SurveyPlan plan = sim::PlanSurvey(target, stations, options, [](int done, int total) {
    std::cout << "plan_survey: predicted " << done << "/" << total << std::endl;
  });
  PrintPrediction("The plan", plan.planned);
  for (size_t k = 0; k < plan.candidates.size(); ++k) {
    PrintPrediction(
        "Candidate " + std::to_string(k + 1) + " (" + plan.candidates[k].description + ")",
        plan.candidates[k].prediction);
  }
  const nlohmann::json settings = {{"structure", structure},
                                   {"stations", stations_path},
                                   {"pixel_noise", options.pixel_noise},
                                   {"lidar_range_noise_m", options.lidar_range_noise_m},
                                   {"lidar_points", options.lidar_points},
                                   {"seed", options.seed}};
  WriteOutputs(output_path, planned, plan, settings);
  std::cout << "plan_survey: wrote " << output_path
            << " (report.json, best_plan.txt, candidates.txt)" << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
