#include "bridge/pipeline/lidar_registration_step.h"

#include "bridge/initialization/lidar_registration_files.h"
#include "colmap_ext/elapsed.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/rigid3_isometry.h"
#include "colmap_ext/trajectory_files.h"
#include "lidar/cloud_io.h"
#include "lidar/lidar_pose_graph.h"
#include "lidar/odometry_registration.h"
#include "lidar/preprocessing.h"
#include "lidar/revisit_closure.h"
#include "lidar/sweep_deskew.h"
#include "lidar/trajectory_refinement.h"
#include "lidar/util/atomic_file.h"
#include "lidar/util/check_option.h"

#include "colmap/scene/reconstruction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
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
                        const std::vector<double>& times,
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
  Trajectory trajectory;
  trajectory.names = names;
  for (const Eigen::Isometry3d& pose : graph.world_from_lidar) {
    trajectory.world_from_sensor.push_back(ToRigid3d(pose));
  }
  if (times.size() == names.size()) trajectory.times = times;
  WriteTrajectoryExports((fs::path(output_path) / "lidar_poses").string(), trajectory);
}

// summary.txt: counts, components, 3-cycles, pose-graph cost, time.
std::string Summary(const std::vector<std::string>& names,
                    const LidarGraph& graph,
                    double seconds) {
  std::ostringstream summary;
  summary << "stations " << names.size() << "\npairs_attempted "
          << graph.edges.size() + graph.refused.size() << "\nbridge_pairs_attempted "
          << graph.num_bridge_pairs << "\nedges_accepted " << graph.edges.size() << "\ncomponents "
          << graph.num_components << "\n";
  for (int c = 0; c < graph.num_components; ++c) {
    summary << "component " << c << ":";
    for (size_t i = 0; i < names.size(); ++i) {
      if (graph.component[i] == c) summary << " " << names[i];
    }
    summary << "\n";
  }
  summary << "speed_reregistered " << graph.num_speed_reregistered << "\nthree_cycles "
          << graph.num_cycles << "\nworst_cycle_translation_m " << graph.worst_cycle_translation_m
          << "\nworst_cycle_rotation_deg " << graph.worst_cycle_rotation_deg << "\n";
  summary << "pose_graph_cost_initial " << graph.refinement_initial_cost
          << "\npose_graph_cost_final " << graph.refinement_final_cost << "\nseconds " << seconds
          << "\n";
  return summary.str();
}

}  // namespace

std::vector<fs::path> StationCloudFiles(const std::string& lidar_path) {
  THROW_CHECK(fs::is_directory(lidar_path)) << "No such folder: " << lidar_path;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(lidar_path)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".pcd" || ext == ".ply" || ext == ".bin") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  for (size_t i = 1; i < files.size(); ++i) {
    if (files[i].stem() == files[i - 1].stem()) {
      throw std::runtime_error("station " + files[i].stem().string() + " has two clouds in " +
                               lidar_path + ": " + files[i - 1].filename().string() + " and " +
                               files[i].filename().string() + " (keep one)");
    }
  }
  THROW_CHECK_GE(files.size(), 2) << "Fewer than 2 clouds in " << lidar_path;
  return files;
}

bool LidarRegistratorStepOptions::Check() const {
  CHECK_OPTION_GE(max_neighbors, 0);
  CHECK_OPTION_GE(sequential, 0);
  CHECK_OPTION_GE(bridge_neighbors, 0);
  CHECK_OPTION_GE(refine_neighbors, 0);
  return sweep_timing.Check() && moving.Check() && odometry.Check() && revisit.Check();
}

bool LidarRegistratorStepOptions::RemovesMovingPoints() const {
  if (remove_moving_points == MovingPointRemoval::kAuto) return deskew_sweeps;
  return remove_moving_points == MovingPointRemoval::kOn;
}

LidarGraphOptions LidarRegistratorStepOptions::GraphOptions() const {
  LidarGraphOptions counted = graph;
  counted.bridge_neighbors = static_cast<size_t>(bridge_neighbors);
  counted.max_neighbors = static_cast<size_t>(max_neighbors);
  counted.sequential = static_cast<size_t>(sequential);
  return counted;
}

namespace {

// The sweep read from `file`, de-skewed; per-point times that do not time it are an error naming
// the file.
PointCloud DeskewFileSweep(const fs::path& file,
                           const PointCloud& raw,
                           const SweepMotion& motion,
                           const SweepTimingOptions& timing) {
  try {
    return DeskewSweep(raw, motion, timing);
  } catch (const std::invalid_argument& error) {
    throw std::runtime_error(file.string() + ": " + error.what());
  }
}

// Reads, optionally de-skews (motion per sweep given), prepares and registers the clouds; prints
// progress. With `deskewed_path`, each de-skewed cloud is written there as <station>.pcd.
LidarGraph RegisterClouds(const std::vector<fs::path>& files,
                          const LidarRegistratorStepOptions& options,
                          const std::vector<SweepMotion>* sweep_motions,
                          const std::string& deskewed_path,
                          const std::vector<double>& frame_indices,
                          const std::chrono::steady_clock::time_point& start) {
  std::vector<std::unique_ptr<StationCloud>> stations;
  for (size_t i = 0; i < files.size(); ++i) {
    CloudReadStats stats;
    PointCloud raw = ReadStationCloud(files[i].string(), &stats);
    if (sweep_motions != nullptr) {
      raw = DeskewFileSweep(files[i], raw, (*sweep_motions)[i], options.sweep_timing);
      WritePointCloud((fs::path(deskewed_path) / (files[i].stem().string() + ".pcd")).string(),
                      raw);
    }
    stations.push_back(PrepareStationCloud(raw, options.cloud));
    std::cout << "lidar_registrator: " << files[i].stem().string() << ": " << raw.Size()
              << " points (" << stats.num_dropped_non_finite << " non-finite dropped"
              << (sweep_motions ? ", de-skewed" : "") << "), " << stations.back()->cloud.Size()
              << " after voxel " << options.cloud.voxel_size << " m, "
              << stations.back()->features.size() << " BSC features [" << std::fixed
              << std::setprecision(1) << SecondsSince(start) << " s]" << std::defaultfloat
              << std::setprecision(6) << std::endl;
  }
  std::vector<const StationCloud*> pointers;
  for (const auto& s : stations) pointers.push_back(s.get());
  const auto progress = [&](size_t done, size_t total) {
    if (done % 10 == 0 || done == total) {
      std::cout << "lidar_registrator: registered " << done << "/" << total << " pairs ["
                << std::fixed << std::setprecision(1) << SecondsSince(start) << " s]"
                << std::defaultfloat << std::setprecision(6) << std::endl;
    }
  };
  return RegisterAllStations(pointers, options.GraphOptions(), progress, frame_indices);
}

// The frame index of each station: its name when every name is a number (KITTI's %010d, possibly
// imported with a step), else its position in name order.
std::vector<double> FrameIndices(const std::vector<std::string>& names) {
  std::vector<double> frames;
  for (const std::string& name : names) {
    size_t used = 0;
    try {
      frames.push_back(static_cast<double>(std::stoll(name, &used)));
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != name.size() || used == 0) {
      frames.clear();
      for (size_t i = 0; i < names.size(); ++i) frames.push_back(static_cast<double>(i));
      return frames;
    }
  }
  return frames;
}

}  // namespace

std::vector<double> SweepClock(const StationDataset& dataset) {
  return dataset.sweep_times.empty() ? FrameIndices(dataset.stations)
                                     : SweepClockFromTimes(dataset.sweep_times);
}

namespace {

// Flags the moving points of the registered clouds (`cloud_paths`, in station order), writes every
// cloud without them to `static_path`/<station>.pcd and all of them, in the world of the first
// station's component, to `moving_ply`; prints the share removed.
void RemoveMovingPoints(const std::vector<std::string>& names,
                        const std::vector<std::string>& cloud_paths,
                        const LidarGraph& graph,
                        const MovingPointOptions& options,
                        const fs::path& static_path,
                        const fs::path& moving_ply) {
  std::vector<PointCloud> clouds(names.size());
  std::vector<const std::vector<Eigen::Vector3d>*> points(names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    clouds[i] = ReadStationCloud(cloud_paths[i]);
    points[i] = &clouds[i].points;
  }
  const auto flags = FlagMovingPoints(points, graph.world_from_lidar, graph.component, options);
  fs::create_directories(static_path);
  PointCloud moving;
  size_t num_points = 0;
  for (size_t i = 0; i < names.size(); ++i) {
    std::vector<size_t> kept;
    for (size_t k = 0; k < flags[i].size(); ++k) {
      if (!flags[i][k]) {
        kept.push_back(k);
      } else if (graph.component[i] == graph.component[0]) {
        moving.points.push_back(graph.world_from_lidar[i] * clouds[i].points[k]);
      }
    }
    num_points += flags[i].size();
    WritePointCloud((static_path / (names[i] + ".pcd")).string(), SelectPoints(clouds[i], kept));
  }
  WritePointCloud(moving_ply.string(), moving);
  std::cout << "lidar_registrator: " << moving.Size() << " of " << num_points << " points ("
            << std::setprecision(2) << 100.0 * moving.Size() / std::max<size_t>(num_points, 1)
            << std::setprecision(6) << " %) lie where a neighbouring cloud saw free space: moving "
            << "objects, left out of " << static_path.string() << " (they are in "
            << moving_ply.string() << ")" << std::endl;
}

// The method asked for; auto: the odometry for the sweeps of a moving platform (de-skewed, or
// rig.json says the platform moves), the pairwise path for tripod stations. Says which and why.
bool UseOdometry(const LidarRegistratorStepOptions& options) {
  if (options.method != RegistrationMethod::kAuto) {
    return options.method == RegistrationMethod::kOdometry;
  }
  const bool sweeps = options.deskew_sweeps || options.moving_platform;
  std::cout << "lidar_registrator: "
            << (sweeps ? "odometry (frame-to-map ICP): the clouds are sweeps of a moving platform"
                       : "pairwise registration (BSC + RANSAC + ICP): the clouds are stations")
            << " (--method auto)" << std::endl;
  return sweeps;
}

void WriteDeskewedSweeps(const std::vector<fs::path>& files,
                         const std::vector<SweepMotion>& motions,
                         const SweepTimingOptions& timing,
                         const fs::path& deskewed_path) {
  for (size_t i = 0; i < files.size(); ++i) {
    const PointCloud raw = ReadStationCloud(files[i].string());
    WritePointCloud((deskewed_path / (files[i].stem().string() + ".pcd")).string(),
                    DeskewFileSweep(files[i], raw, motions[i], timing));
  }
}

// OUTPUT/odometry.csv: one line per frame of the odometry's diagnostics.
void WriteOdometryTable(const fs::path& path,
                        const std::vector<std::string>& names,
                        const std::vector<OdometryFrame>& frames) {
  std::ostringstream csv;
  csv << "# frame, converged, iterations, source points, correspondences, threshold m, rms m, "
         "plane rms m, constraint ratio, weakest axis, degenerate, sigma tx ty tz [m], sigma rx ry "
         "rz [deg] (empty: no covariance)\n";
  for (size_t k = 0; k < frames.size(); ++k) {
    const OdometryFrame& f = frames[k];
    csv << names[k] << "," << f.converged << "," << f.num_iterations << "," << f.num_source_points
        << "," << f.num_correspondences << "," << f.threshold_m << "," << f.rms_m << ","
        << f.plane_rms_m << "," << f.constraints.weakest_ratio << ","
        << f.constraints.WeakestAxisName() << "," << f.degenerate;
    for (int a = 0; a < 6; ++a) {
      const int index = a < 3 ? a + 3 : a - 3;  // translation first
      csv << ",";
      if (f.covariance) {
        csv << std::sqrt((*f.covariance)(index, index)) * (a < 3 ? 1.0 : 180.0 / M_PI);
      }
    }
    csv << "\n";
  }
  WriteFileAtomically(path.string(), csv.str());
}

LidarGraph RegisterByOdometry(const std::vector<fs::path>& files,
                              const std::vector<double>& clock,
                              const LidarRegistratorStepOptions& options,
                              const std::string& output_path,
                              std::string* method_line) {
  LidarOdometryOptions odometry = options.odometry;
  odometry.deskew = options.deskew_sweeps;
  odometry.timing = options.sweep_timing;
  std::vector<std::string> paths, names;
  for (const fs::path& file : files) {
    paths.push_back(file.string());
    names.push_back(file.stem().string());
  }
  const auto progress = [](size_t done, size_t total) {
    if (done % 50 == 0 || done == total) {
      std::cout << "lidar_registrator: odometry " << done << "/" << total << " frames" << std::endl;
    }
  };
  const OdometryRegistration result = RegisterSweepsByOdometry(paths, clock, odometry, progress);
  size_t degenerate = 0;
  for (size_t k = 0; k < result.frames.size(); ++k) {
    if (!result.frames[k].degenerate) continue;
    ++degenerate;
    std::cout << "lidar_registrator: WARNING: frame " << names[k] << " is degenerate (weakest "
              << result.frames[k].constraints.WeakestAxisName() << ", ratio "
              << result.frames[k].constraints.weakest_ratio << "): its pose is the odometry's "
              << "best guess along that direction" << std::endl;
  }
  const double rate = result.frames.size() / std::max(result.seconds_registering, 1e-9);
  std::cout << "lidar_registrator: odometry registered " << result.frames.size() << " frames at "
            << std::fixed << std::setprecision(1) << rate << " frames/s" << std::defaultfloat
            << std::setprecision(6) << ", " << degenerate << " degenerate" << std::endl;
  fs::create_directories(output_path);
  WriteOdometryTable(fs::path(output_path) / "odometry.csv", names, result.frames);
  std::ostringstream line;
  line << "method odometry (frames of a moving platform: frame-to-map "
          "ICP)\nodometry_frames_per_second "
       << rate << "\ndegenerate_frames " << degenerate << "\n";
  *method_line = line.str();
  return result.graph;
}

// The odometry's trajectory refined by ICP between neighbouring sweeps of `cloud_paths`
// (lidar/trajectory_refinement.h); prints what it did and returns the summary's lines.
std::string RefineOdometryTrajectory(const std::vector<std::string>& cloud_paths,
                                     const LidarRegistratorStepOptions& options,
                                     LidarGraph* graph) {
  TrajectoryRefinementOptions refine;
  refine.neighbors = options.refine_neighbors;
  refine.cloud = options.cloud;
  refine.pair = options.graph.pair;
  refine.drift = options.revisit.drift;
  const auto progress = [](size_t done, size_t total) {
    if (done % 50 == 0 || done == total) {
      std::cout << "lidar_registrator: refining " << done << "/" << total << " frames" << std::endl;
    }
  };
  const TrajectoryRefinement refinement = RefineTrajectory(cloud_paths, refine, graph, progress);
  std::cout << "lidar_registrator: refined the trajectory with " << refinement.num_accepted
            << " of " << refinement.num_pairs << " neighbour pairs [" << std::fixed
            << std::setprecision(1) << refinement.seconds << " s]" << std::defaultfloat
            << std::setprecision(6) << std::endl;
  std::ostringstream lines;
  lines << "refined_pairs " << refinement.num_pairs << "\nrefined_pairs_accepted "
        << refinement.num_accepted << "\n";
  return lines.str();
}

// Revisit edges of the odometry's trajectory (lidar/revisit_closure.h) between the clouds of
// `cloud_paths`; prints each revisit and returns the summary's lines.
std::string CloseOdometryRevisits(const std::vector<std::string>& cloud_paths,
                                  const std::vector<fs::path>& files,
                                  const LidarRegistratorStepOptions& options,
                                  LidarGraph* graph) {
  RevisitOptions revisit = options.revisit;
  revisit.cloud = options.cloud;
  revisit.pair = options.graph.pair;
  const RevisitClosure closure = CloseRevisits(cloud_paths, revisit, graph);
  const auto print = [&](const RevisitEdge& r, const char* verdict) {
    std::cout << "lidar_registrator: revisit " << files[r.edge.source].stem().string() << " -> "
              << files[r.edge.target].stem().string() << " " << verdict;
    if (r.chi2 >= 0) std::cout << " (chi2 " << r.chi2 << ", bound " << revisit.max_chi2 << ")";
    if (!r.edge.registration.accepted) std::cout << ": " << r.edge.registration.reason;
    std::cout << std::endl;
  };
  for (const RevisitEdge& r : closure.accepted) print(r, "accepted");
  for (const RevisitEdge& r : closure.refused) print(r, "refused");
  std::cout << "lidar_registrator: " << closure.num_candidates << " revisit candidates among "
            << closure.num_keyframes << " keyframes, " << closure.accepted.size() << " accepted ["
            << std::fixed << std::setprecision(1) << closure.seconds << " s]" << std::defaultfloat
            << std::setprecision(6) << std::endl;
  std::ostringstream lines;
  lines << "revisit_keyframes " << closure.num_keyframes << "\nrevisit_candidates "
        << closure.num_candidates << "\nrevisit_edges " << closure.accepted.size()
        << "\nrevisit_edges_refused " << closure.refused.size() << "\n";
  return lines.str();
}

// After the odometry and its de-skewing: the refinement by neighbouring sweeps (then de-skewing
// again) and the revisits, on the de-skewed sweeps. Returns the summary's lines.
std::string RefineAndCloseOdometry(const std::vector<fs::path>& files,
                                   const std::vector<double>& clock,
                                   const LidarRegistratorStepOptions& options,
                                   const std::string& output_path,
                                   LidarGraph* graph) {
  const fs::path deskewed_path = fs::path(output_path) / "deskewed";
  std::vector<std::string> cloud_paths;
  for (const fs::path& file : files) {
    cloud_paths.push_back(options.deskew_sweeps
                              ? (deskewed_path / (file.stem().string() + ".pcd")).string()
                              : file.string());
  }
  std::string lines;
  if (options.refine_neighbors > 0) {
    lines += RefineOdometryTrajectory(cloud_paths, options, graph);
    if (options.deskew_sweeps) {
      std::cout << "lidar_registrator: de-skewing every sweep again with the refined motion"
                << std::endl;
      WriteDeskewedSweeps(files,
                          SweepMotionsFromPoses(graph->world_from_lidar, clock, graph->component),
                          options.sweep_timing,
                          deskewed_path);
    }
  }
  if (options.revisits) lines += CloseOdometryRevisits(cloud_paths, files, options, graph);
  return lines;
}

// The registration by the chosen method, then (sweeps) de-skewing with its motion: the odometry's
// poses stand; the pairwise path registers the de-skewed sweeps again.
LidarGraph RegisterStations(const std::vector<fs::path>& files,
                            const std::vector<double>& clock,
                            const LidarRegistratorStepOptions& options,
                            const std::string& output_path,
                            const std::chrono::steady_clock::time_point& start,
                            std::string* method_line) {
  // Sweeps of a moving platform: their frames in time order turn on the speed check.
  const std::vector<double> frames =
      options.deskew_sweeps || options.sequential > 0 ? clock : std::vector<double>();
  const bool odometry = UseOdometry(options);
  LidarGraph graph;
  if (odometry) {
    graph = RegisterByOdometry(files, clock, options, output_path, method_line);
  } else {
    *method_line = "method pairwise (BSC + RANSAC + ICP over station pairs)\n";
    graph = RegisterClouds(files, options, nullptr, "", frames, start);
  }
  if (options.deskew_sweeps) {
    std::cout << "lidar_registrator: de-skewing every sweep with the registered motion"
              << (odometry ? "" : " and registering again") << std::endl;
    const std::vector<SweepMotion> motions =
        SweepMotionsFromPoses(graph.world_from_lidar, clock, graph.component);
    const fs::path deskewed_path = fs::path(output_path) / "deskewed";
    fs::create_directories(deskewed_path);
    if (odometry) {
      WriteDeskewedSweeps(files, motions, options.sweep_timing, deskewed_path);
    } else {
      graph = RegisterClouds(files, options, &motions, deskewed_path.string(), frames, start);
    }
  }
  if (odometry) *method_line += RefineAndCloseOdometry(files, clock, options, output_path, &graph);
  return graph;
}

}  // namespace

void RunLidarRegistratorStep(const std::string& lidar_path,
                             const std::string& output_path,
                             LidarRegistratorStepOptions options) {
  THROW_CHECK(options.Check());
  const std::vector<fs::path> files = StationCloudFiles(lidar_path);
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::string> names;
  for (const fs::path& file : files) names.push_back(file.stem().string());
  const fs::path deskewed_path = fs::path(output_path) / "deskewed";
  const fs::path static_path = fs::path(output_path) / "static";
  fs::remove_all(deskewed_path);
  fs::remove_all(static_path);  // with moving_points.ply: no stale output of an earlier run
  fs::remove(fs::path(output_path) / "moving_points.ply");
  THROW_CHECK(options.sweep_clock.empty() || options.sweep_clock.size() == names.size())
      << "sweep times for " << options.sweep_clock.size() << " stations, but " << names.size()
      << " clouds in " << lidar_path;
  const std::vector<double> clock =
      options.sweep_clock.empty() ? FrameIndices(names) : options.sweep_clock;
  std::string method_line;
  LidarGraph graph = RegisterStations(files, clock, options, output_path, start, &method_line);
  fs::create_directories(output_path);
  if (options.RemovesMovingPoints()) {
    std::vector<std::string> cloud_paths;
    for (const fs::path& file : files) {
      cloud_paths.push_back(options.deskew_sweeps
                                ? (deskewed_path / (file.stem().string() + ".pcd")).string()
                                : file.string());
    }
    RemoveMovingPoints(names,
                       cloud_paths,
                       graph,
                       options.moving,
                       static_path,
                       fs::path(output_path) / "moving_points.ply");
  }
  WritePairsAndPoses(output_path, names, options.station_times, graph);
  const std::string summary = method_line + Summary(names, graph, SecondsSince(start));
  WriteFileAtomically((fs::path(output_path) / "summary.txt").string(), summary);
  std::cout << summary;
  if (graph.num_components > 1) {
    std::cout << "lidar_registrator: WARNING: the stations form " << graph.num_components
              << " disconnected components (see summary.txt)" << std::endl;
  }
}

void RunDeskewSweepsStep(const StationDataset& dataset,
                         const std::string& model_path,
                         const std::string& output_path) {
  if (!dataset.rig.lidar_sweep) {
    throw std::runtime_error(dataset.root +
                             "/rig.json has no lidar.sweep: its clouds are not sweeps of a moving "
                             "platform, and there is nothing to de-skew");
  }
  SweepTimingOptions timing;
  timing.start_azimuth_deg = dataset.rig.lidar_sweep->start_azimuth_deg;
  timing.counter_clockwise = dataset.rig.lidar_sweep->counter_clockwise;
  colmap::Reconstruction model;
  model.Read(model_path);
  const Eigen::Isometry3d cam_from_lidar =
      ToIsometry(ReadPoseFile((fs::path(model_path) / "cam_from_lidar.txt").string()));
  // Stations outside the model get a component of their own: their neighbours' motion is mirrored.
  std::vector<Eigen::Isometry3d> world_from_lidar(dataset.stations.size(),
                                                  Eigen::Isometry3d::Identity());
  std::vector<int> component(dataset.stations.size());
  size_t num_in_model = 0;
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    const colmap::Image* image = model.FindImageWithName(dataset.LeftImageName(i));
    component[i] = image ? 0 : static_cast<int>(i) + 1;
    if (image) {
      world_from_lidar[i] = ToIsometry(colmap::Inverse(image->CamFromWorld())) * cam_from_lidar;
      ++num_in_model;
    }
  }
  if (num_in_model < 2) {
    throw std::runtime_error(model_path + " holds " + std::to_string(num_in_model) +
                             " of the station images of " + dataset.root + " (named like " +
                             dataset.LeftImageName(0) + "): no trajectory to de-skew with");
  }
  const std::vector<SweepMotion> motions =
      SweepMotionsFromPoses(world_from_lidar, SweepClock(dataset), component);
  PartialOutputFolder partial(output_path);
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    const PointCloud raw = ReadStationCloud(dataset.cloud_paths[i]);
    WritePointCloud(partial.File(dataset.stations[i] + ".pcd"),
                    DeskewFileSweep(dataset.cloud_paths[i], raw, motions[i], timing));
  }
  partial.Commit();
  std::cout << "deskew_sweeps: " << dataset.stations.size()
            << " sweeps de-skewed with the motion of " << model_path << " into " << output_path
            << std::endl;
}

}  // namespace colmap_lidar
