#include "bridge/pipeline/initialization_step.h"

#include "bridge/initialization/model_completion.h"
#include "bridge/pipeline/capture_profile.h"
#include "bridge/pipeline/stereo_alignment_report.h"
#include "colmap_ext/elapsed.h"
#include "colmap_ext/logging.h"
#include "lidar/util/atomic_file.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <optional>
#include <vector>

namespace colmap_lidar {
namespace {

std::vector<double> ToVector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// initialization.json's account of the travel-direction-and-structure start.
nlohmann::json TravelStructureJson(const TravelStructureExtrinsic& estimate) {
  const ExtrinsicAlignmentResult& alignment = estimate.alignment;
  return {{"valid", estimate.valid},
          {"message", estimate.message},
          {"travel_in_cam", ToVector(estimate.travel_in_cam)},
          {"travel_in_lidar", ToVector(estimate.travel_in_lidar)},
          {"direction_pairs", estimate.num_direction_pairs},
          {"direction_rms_deg", estimate.direction_rms_deg},
          {"stations", estimate.num_stations},
          {"roll_deg", estimate.roll.best_roll_deg},
          {"roll_rms_m", estimate.roll.best_rms_m},
          {"runner_up_roll_deg", estimate.roll.runner_up_roll_deg},
          {"runner_up_rms_m", estimate.roll.runner_up_rms_m},
          {"associations", alignment.num_associations},
          {"rms_m", alignment.rms_m},
          {"sigma_rotation_deg", ToVector(alignment.sigma_rotation_deg)},
          {"sigma_translation_m", ToVector(alignment.sigma_translation_m)}};
}

void WriteInitializationReport(const std::string& path,
                               const PoseInitialization& init,
                               const std::string& input_path,
                               const std::vector<double>& scales) {
  nlohmann::json report;
  report["extrinsic_source"] = init.extrinsic_source;
  report["hand_eye"] = {{"unique", init.hand_eye.unique},
                        {"message", init.hand_eye.message},
                        {"motions", init.hand_eye.num_motions},
                        {"max_axis_angle_deg", init.hand_eye.max_axis_angle_deg}};
  report["image_edges"] = init.num_image_edges;
  report["lidar_edges"] = init.num_lidar_edges;
  report["lidar_edges_contradicted_by_images"] = init.contradicted_lidar_edges;
  report["edges_breaking_cycles"] = init.inconsistent_edges;
  report["degenerate_lidar_edges_left_out"] = nlohmann::json::array();
  for (const LidarPairRecord& pair : init.degenerate_lidar_edges) {
    report["degenerate_lidar_edges_left_out"].push_back(DescribeDegenerateEdge(pair));
  }
  report["edges_disagreeing_with_the_pose_graph"] = init.disagreeing_edges;
  report["stations"] = init.cam_from_world.size();
  report["unreachable"] = init.unreachable;
  report["input_model"] = input_path;
  report["scale_to_metres"] = scales.front();
  if (!input_path.empty()) report["model_scales_to_metres"] = scales;
  report["unreachable_reasons"] = init.unreachable_reason;
  if (init.stereo_alignment)
    report["stereo_alignment"] = StereoAlignmentJson(*init.stereo_alignment);
  if (init.travel_structure)
    report["travel_structure"] = TravelStructureJson(*init.travel_structure);
  if (init.hand_eye.unobservable_axis_in_cam.squaredNorm() > 0) {
    const Eigen::Vector3d& axis = init.hand_eye.unobservable_axis_in_cam;
    report["hand_eye"]["unobservable_translation_axis_in_cam"] = {axis.x(), axis.y(), axis.z()};
  }
  WriteFileAtomically(path, report.dump(2) + "\n");
}

// The start's source, and a WARNING per loop that does not close and per station left out.
void PrintInitialization(const PoseInitialization& init) {
  std::cout << "cam_from_lidar: " << init.extrinsic_source
            << "; hand-eye: " << init.hand_eye.message << std::endl;
  for (const std::string& edge : init.disagreeing_edges) {
    std::cout << "WARNING: edge " << edge
              << ": a loop of edges does not close; the stations it joins may be placed wrong"
              << std::endl;
  }
  for (const std::string& name : init.unreachable) {
    const auto reason = init.unreachable_reason.find(name);
    std::cout << "WARNING: station image " << name << " is not in the model ("
              << (reason == init.unreachable_reason.end() ? "no image or LiDAR edge reaches it"
                                                          : reason->second)
              << ")" << std::endl;
  }
}

// The capture profile the later steps follow: the hand-eye's one rotation axis, if it found one.
CaptureProfile ProfileOf(const StationDataset& dataset, const PoseInitialization& init) {
  std::optional<Eigen::Vector3d> one_axis;
  if (init.hand_eye.unobservable_axis_in_cam.squaredNorm() > 0) {
    one_axis = init.hand_eye.unobservable_axis_in_cam;
  }
  return DecideCaptureProfile(dataset, one_axis);
}

}  // namespace

CaptureProfile RunPoseInitializerStep(const StationDataset& dataset,
                                      const PoseInitializerPaths& paths,
                                      const PoseInitializerOptions& options) {
  THROW_CHECK(options.Check());
  const auto start = std::chrono::steady_clock::now();
  PartialOutputFolder partial(paths.output_path);
  PoseInitialization init;
  std::vector<double> scales{1.0};
  if (paths.input_path.empty() && !dataset.rig.IsStereo()) {
    std::cout << "Monocular dataset: stations placed through their LiDAR poses" << std::endl;
    init = InitializeMonocular(paths.database_path, dataset, paths.registration_path, options);
    scales = {init.hand_eye.scale};
  } else if (paths.input_path.empty()) {
    init = InitializePoses(
        paths.database_path, dataset, paths.registration_path, options, paths.depth_path);
    std::cout << "Pose graph: " << init.num_image_edges << " image edges (A_c), "
              << init.num_lidar_edges << " LiDAR edges (A_l); " << init.cam_from_world.size()
              << " stations reachable" << std::endl;
  } else {
    ExistingModels existing{ReadModels(paths.input_path), {}};
    init = InitializeFromModels(paths.database_path,
                                dataset,
                                paths.registration_path,
                                options,
                                &existing,
                                paths.depth_path);
    const std::vector<colmap::Reconstruction>& models = existing.models;
    scales = existing.scales;
    for (size_t k = 0; k < models.size(); ++k) {
      std::cout << "Model " << k << " (" << models[k].NumRegImages()
                << " registered images) rescaled to metres by " << scales[k] << std::endl;
    }
    std::cout << "Completed through the LiDAR: " << init.cam_from_world.size() << " stations from "
              << init.num_image_edges << " model edges and " << init.num_lidar_edges
              << " LiDAR edges (A_l)" << std::endl;
  }
  TriangulateInitialModel(paths.database_path, init, partial.Path());
  PrintInitialization(init);
  WritePoseFile(partial.File("cam_from_lidar.txt"),
                "initial cam_from_lidar (" + init.extrinsic_source + "); qw qx qy qz tx ty tz",
                init.cam_from_lidar);
  WriteInitializationReport(partial.File("initialization.json"), init, paths.input_path, scales);
  const CaptureProfile profile = ProfileOf(dataset, init);
  WriteCaptureProfile(partial.File(kCaptureProfileFile), profile);
  partial.Commit();
  std::cout << "Wrote the initial model to " << paths.output_path << " (" << std::fixed
            << std::setprecision(1) << SecondsSince(start) << " s)" << std::endl;
  return profile;
}

}  // namespace colmap_lidar
