#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "bridge/lidar_registration_files.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/rigid3_isometry.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "lidar/lidar_pose_graph.h"

#include "colmap/controllers/option_manager.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

LidarPairRecord ToRecord(const std::vector<std::string>& names, const LidarEdge& e) {
  LidarPairRecord record;
  record.target = names[e.target];
  record.source = names[e.source];
  record.target_from_source = ToRigid3d(e.target_from_source);
  record.num_inliers = e.registration.num_inliers;
  record.overlap = e.registration.overlap;
  record.rmse_m = e.registration.rmse;
  record.noise_m = e.registration.noise_rms;
  record.constraint_ratio = e.registration.constraints.weakest_ratio;
  record.weakest_axis = e.registration.constraints.WeakestAxisName();
  record.degenerate = e.registration.degenerate;
  record.from_identity = e.registration.from_identity;
  return record;
}

// pairs.txt (accepted edges, refused pairs as comments with the reason) and lidar_poses.txt.
void WritePairsAndPoses(const std::string& output_path,
                        const std::vector<std::string>& names,
                        const LidarGraph& graph) {
  std::vector<LidarPairRecord> accepted;
  for (const LidarEdge& e : graph.edges) accepted.push_back(ToRecord(names, e));
  std::vector<RefusedLidarPair> refused;
  for (const LidarEdge& e : graph.refused) {
    refused.push_back({names[e.target], names[e.source], e.registration.reason});
  }
  WriteLidarPairs((fs::path(output_path) / "pairs.txt").string(), accepted, refused);
  std::map<std::string, colmap::Rigid3d> poses;
  for (size_t i = 0; i < names.size(); ++i) poses[names[i]] = ToRigid3d(graph.world_from_lidar[i]);
  WriteNamedPoses((fs::path(output_path) / "lidar_poses.txt").string(),
                  "LiDAR station poses world_from_lidar (world = first station "
                  "of each component)",
                  poses);
}

// summary.txt: counts, components, 3-cycles, pose-graph cost, time.
std::string Summary(const std::vector<std::string>& names,
                    const LidarGraph& graph,
                    double seconds) {
  std::ostringstream summary;
  summary << "stations " << names.size() << "\npairs_attempted "
          << graph.edges.size() + graph.refused.size() << "\nedges_accepted " << graph.edges.size()
          << "\ncomponents " << graph.num_components << "\n";
  for (int c = 0; c < graph.num_components; ++c) {
    summary << "component " << c << ":";
    for (size_t i = 0; i < names.size(); ++i) {
      if (graph.component[i] == c) summary << " " << names[i];
    }
    summary << "\n";
  }
  summary << "three_cycles " << graph.num_cycles << "\nworst_cycle_translation_m "
          << graph.worst_cycle_translation_m << "\nworst_cycle_rotation_deg "
          << graph.worst_cycle_rotation_deg << "\n";
  summary << "pose_graph_cost_initial " << graph.refinement_initial_cost
          << "\npose_graph_cost_final " << graph.refinement_final_cost << "\nseconds " << seconds
          << "\n";
  return summary.str();
}

// The station clouds of a folder (.pcd, .ply, .bin), sorted by name; at least two.
std::vector<fs::path> StationCloudFiles(const std::string& lidar_path) {
  THROW_CHECK(fs::is_directory(lidar_path)) << "No such folder: " << lidar_path;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(lidar_path)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".pcd" || ext == ".ply" || ext == ".bin") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  THROW_CHECK_GE(files.size(), 2) << "Fewer than 2 clouds in " << lidar_path;
  return files;
}

}  // namespace

bool LidarRegistratorStepOptions::Check() {
  CHECK_OPTION_GE(max_neighbors, 0);
  CHECK_OPTION_GE(sequential, 0);
  graph.max_neighbors = static_cast<size_t>(max_neighbors);
  graph.sequential = static_cast<size_t>(sequential);
  return true;
}

void AddLidarRegistratorOptions(const std::string& prefix,
                                colmap::OptionManager* manager,
                                LidarRegistratorStepOptions* options) {
  PrefixedOptions add(manager, prefix);
  StationCloudOptions& cloud = options->cloud;
  PairRegistrationOptions& pair = options->graph.pair;
  add.Add("voxel_size", &cloud.voxel_size, "ICP/normals voxel [m]");
  add.Add("feature_voxel_size", &cloud.feature_voxel_size);
  add.Add("bsc_support_radius", &cloud.bsc.support_radius);
  add.Add("max_neighbors",
          &options->max_neighbors,
          "0: all pairs; k: the k most similar stations each");
  add.Add("sequential",
          &options->sequential,
          "k > 0: register each frame with its k successors (sweeps)");
  add.Add("min_overlap", &pair.min_overlap);
  add.Add("max_rmse_to_noise", &pair.max_rmse_to_noise, "ICP RMSE / the clouds' own plane noise");
  add.Add("max_rmse", &pair.max_rmse, "absolute cap [m]; 0: none");
  add.Add("try_identity", &pair.try_identity);
  add.Add("min_constraint_ratio", &pair.min_constraint_ratio);
  add.Add("weak_constraint_ratio", &pair.weak_constraint_ratio);
  add.Add("check_cycles", &options->graph.check_cycles);
  add.Add("max_cycle_translation_m", &options->graph.cycles.max_translation_m);
  add.Add("max_cycle_rotation_deg", &options->graph.cycles.max_rotation_deg);
  add.Add("robust_loss_sigmas", &options->graph.robust_loss_sigmas);
}

void RunLidarRegistratorStep(const std::string& lidar_path,
                             const std::string& output_path,
                             LidarRegistratorStepOptions options) {
  THROW_CHECK(options.Check());
  const std::vector<fs::path> files = StationCloudFiles(lidar_path);
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::string> names;
  std::vector<std::unique_ptr<StationCloud>> stations;
  for (const fs::path& file : files) {
    CloudReadStats stats;
    const PointCloud raw = ReadPointCloud(file.string(), &stats);
    stations.push_back(PrepareStationCloud(raw, options.cloud));
    names.push_back(file.stem().string());
    std::cout << "lidar_registrator: " << names.back() << ": " << raw.Size() << " points ("
              << stats.num_dropped_non_finite << " non-finite dropped), "
              << stations.back()->cloud.Size() << " after voxel " << options.cloud.voxel_size
              << " m, " << stations.back()->features.size() << " BSC features [" << std::fixed
              << std::setprecision(1) << SecondsSince(start) << " s]" << std::defaultfloat
              << std::setprecision(6) << std::endl;
  }
  std::vector<const StationCloud*> pointers;
  for (const auto& s : stations) pointers.push_back(s.get());
  const LidarGraph graph =
      RegisterAllStations(pointers, options.graph, [&](size_t done, size_t total) {
        if (done % 10 == 0 || done == total) {
          std::cout << "lidar_registrator: registered " << done << "/" << total << " pairs ["
                    << std::fixed << std::setprecision(1) << SecondsSince(start) << " s]"
                    << std::defaultfloat << std::setprecision(6) << std::endl;
        }
      });

  fs::create_directories(output_path);
  WritePairsAndPoses(output_path, names, graph);
  const std::string summary = Summary(names, graph, SecondsSince(start));
  WriteFileAtomically((fs::path(output_path) / "summary.txt").string(), summary);
  std::cout << summary;
  if (graph.num_components > 1) {
    std::cout << "lidar_registrator: WARNING: the stations form " << graph.num_components
              << " disconnected components (see summary.txt)" << std::endl;
  }
}

int RunLidarRegistrator(int argc, char** argv) {
  std::string lidar_path, output_path;
  LidarRegistratorStepOptions registrator;
  colmap::OptionManager manager;
  manager.AddRequiredOption("lidar_path", &lidar_path, "folder of station clouds (.pcd/.ply/.bin)");
  manager.AddRequiredOption("output_path", &output_path, "folder for pairs.txt, lidar_poses.txt");
  AddLidarRegistratorOptions("", &manager, &registrator);
  manager.Parse(argc, argv);
  THROW_CHECK(registrator.Check());  // before any file is read
  RunLidarRegistratorStep(lidar_path, output_path, registrator);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
