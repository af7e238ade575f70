#include "bridge/pipeline/joint_step.h"

#include "bridge/evaluation/trajectory_evaluation.h"
#include "bridge/initialization/track_triangulation.h"
#include "bridge/joint/association_settling.h"
#include "bridge/joint/start_departure.h"
#include "bridge/pipeline/capture_profile.h"
#include "bridge/pipeline/joint_report.h"
#include "bridge/pipeline/vertical_alignment_step.h"
#include "colmap_ext/elapsed.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/trajectory_files.h"
#include "lidar/util/atomic_file.h"

#include "colmap/scene/reconstruction.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// --cam_from_lidar FILE, else INPUT/cam_from_lidar.txt (pose_initializer's), else rig.json's guess.
colmap::Rigid3d InitialCamFromLidar(const std::string& cam_from_lidar_path,
                                    const std::string& input_path,
                                    const StationDataset& dataset) {
  const std::string model_extrinsic = (fs::path(input_path) / "cam_from_lidar.txt").string();
  if (!cam_from_lidar_path.empty()) return ReadPoseFile(cam_from_lidar_path);
  if (fs::exists(model_extrinsic)) return ReadPoseFile(model_extrinsic);
  if (dataset.rig.cam_from_lidar_guess) return *dataset.rig.cam_from_lidar_guess;
  throw std::runtime_error(
      "no initial cam_from_lidar: pass --cam_from_lidar FILE or add cam_from_lidar_guess to " +
      dataset.root + "/rig.json");
}

// The capture profile the pose initialiser recorded beside the input model; for a model without
// one (e.g. the user's own), the dataset's rig and platform, the stations' rotation then judged from
// the model alone (DecideFromMotion).
CaptureProfile InputCaptureProfile(const StationDataset& dataset, const std::string& input_path) {
  const fs::path path = fs::path(input_path) / kCaptureProfileFile;
  if (!fs::exists(path)) return DecideCaptureProfile(dataset, std::nullopt);
  return ReadCaptureProfile(path.string());
}

// Each registered image's capture time (DATASET/timestamps.txt); empty without times.
std::map<colmap::image_t, double> ImageTimes(const StationDataset& dataset,
                                             const LoadedJointData& loaded) {
  std::map<colmap::image_t, double> times;
  if (dataset.frame_times.size() != dataset.stations.size()) return times;
  for (const auto& [image_id, station] : loaded.station_of_image) {
    times[image_id] = dataset.frame_times[station];
  }
  return times;
}

void PrintMeasurement(const ExtrinsicMeasurement& measurement) {
  const Eigen::Matrix<double, 6, 1> sigmas = measurement.covariance.diagonal().cwiseSqrt();
  std::cout << "cam_from_lidar measured by the " << measurement.source
            << " joins the cost: sigma about the camera axes "
            << sigmas.head<3>().transpose() * 180 / M_PI << " deg, along them "
            << 1000 * sigmas.tail<3>().transpose() << " mm" << std::endl;
}

// rig.json's guess with its sigma, as a prior (isotropic per block about/along the camera axes).
ExtrinsicMeasurement GuessPrior(const StationRig& rig) {
  ExtrinsicMeasurement prior;
  prior.cam_from_lidar = *rig.cam_from_lidar_guess;
  const double rotation = rig.cam_from_lidar_guess_sigma->rotation_deg * M_PI / 180;
  const double translation = rig.cam_from_lidar_guess_sigma->translation_m;
  prior.covariance.diagonal() << rotation * rotation, rotation * rotation, rotation * rotation,
      translation * translation, translation * translation, translation * translation;
  prior.source = "rig.json guess (prior)";
  prior.prior = true;
  return prior;
}

// Decided from the motion (DecideFromMotion). E_m: on for a monocular rig, and for a stereo rig on
// a moving platform (capture_profile.json: rig.json's clouds are sweeps, or a one-axis hand-eye) whose
// stations do not rotate about two axes (the uniqueness test of Zhen et al. 2019 on the input
// model): the paper's terms then leave the roll about the driving direction and the translation to
// the landmarks on the LiDAR surfaces. Not for tripod stations: there the tool asks for tilted stations,
// since E_m on unrotated stations ends far from the truth with a small reported sigma. Off (the
// paper's cost) otherwise.
// Its weight on such a moving platform is kMovingPlatformLandmarkWeight, 1 on tripods: along a
// drive the landmarks' errors are shared (an E_m solve moved the roll by 0.12 deg through its
// associations alone, and the roll's error kept its sign over runs), so E_m counts for less than its
// number of residuals (docs/joint_adjuster.md).
constexpr double kMovingPlatformLandmarkWeight = 0.25;

// In joint mode: rig.json's guess with a sigma as a prior, and with `vertical_alignment` the vertical
// alignment (which the start then takes when significant). Returns the vertical alignment if it ran.
std::optional<VerticalAlignment> AddExtrinsicMeasurements(
    const StationDataset& dataset,
    bool vertical_alignment,
    const colmap::Reconstruction& reconstruction,
    const JointAdjusterStepOptions& options,
    LoadedJointData* loaded,
    colmap::Rigid3d* cam_from_lidar) {
  if (options.adjuster.mode != JointMode::kJoint) return std::nullopt;
  std::vector<ExtrinsicMeasurement>& measurements = loaded->data.extrinsic_measurements;
  if (dataset.rig.cam_from_lidar_guess && dataset.rig.cam_from_lidar_guess_sigma) {
    measurements.push_back(GuessPrior(dataset.rig));
    PrintMeasurement(measurements.back());
  }
  if (!vertical_alignment) return std::nullopt;
  std::optional<VerticalAlignment> vertical = MeasureStationVerticals(
      dataset, reconstruction, *loaded, *cam_from_lidar, options.adjuster.observability);
  if (vertical->valid) {
    measurements.push_back(VerticalAlignmentMeasurement(*vertical, *cam_from_lidar));
    // Start from it when it differs from the start significantly: a drive's hand-eye can leave the
    // roll degrees off, and the first round's wide associations then settle the height wrongly.
    if (vertical->Significant()) {
      cam_from_lidar->rotation = measurements.back().cam_from_lidar.rotation;
    } else {
      std::cout
          << "The vertical alignment's correction is within its uncertainty (95 %): the start "
             "is kept"
          << std::endl;
    }
  }
  return vertical;
}

// What the motion decides: E_m's weight (into `adjuster`) and whether the vertical alignment runs
// (returned): both for a moving platform whose stations do not rotate about two axes.
bool DecideFromMotion(const StationDataset& dataset,
                      const CaptureProfile& profile,
                      const colmap::Reconstruction& reconstruction,
                      JointAdjusterOptions* adjuster) {
  const MotionAnalysis motion = AnalyseMotion(reconstruction, adjuster->observability);
  const bool degenerate_motion = profile.rotation == StationRotation::kOneAxis ||
                                 (!motion.unique && profile.platform == Platform::kMoving);
  adjuster->landmark_lidar_weight =
      degenerate_motion ? kMovingPlatformLandmarkWeight : (dataset.rig.IsStereo() ? 0.0 : 1.0);
  if (degenerate_motion) {
    std::ostringstream weight;  // std::cout may hold a fixed precision of 1
    weight << kMovingPlatformLandmarkWeight;
    std::cout << "A moving platform whose stations do not rotate about two axes (" << motion.verdict
              << "): the landmark-to-LiDAR-plane term is on (weight " << weight.str() << ")"
              << std::endl;
  }
  return degenerate_motion;
}

void PrintWarnings(const StartDeparture& departure, const AssociationSettling& settling) {
  for (const std::string& warning : departure.warnings) {
    std::cout << "WARNING: cam_from_lidar " << warning << std::endl;
  }
  for (const std::string& warning : settling.warnings) {
    std::cout << "WARNING: cam_from_lidar " << warning << std::endl;
  }
}

// The input sparse model; at least two registered images.
colmap::Reconstruction ReadInputModel(const std::string& input_path) {
  THROW_CHECK(fs::is_directory(input_path)) << "no sparse model folder " << input_path;
  colmap::Reconstruction reconstruction;
  reconstruction.Read(input_path);
  THROW_CHECK_GE(reconstruction.NumRegImages(), 2)
      << input_path << " has fewer than 2 registered images";
  return reconstruction;
}

// The clock offset between images and sweeps is estimated on a moving platform only (and when
// asked); it needs each image's time.
void DecideTimeOffset(const StationDataset& dataset,
                      const CaptureProfile& profile,
                      LoadedJointData* loaded,
                      JointAdjusterStepOptions* options) {
  options->adjuster.estimate_time_offset =
      options->estimate_time_offset && profile.IsMovingPlatform();
  if (options->adjuster.estimate_time_offset) {
    loaded->data.image_times = ImageTimes(dataset, *loaded);
  }
}

// Rebuilds the tracks at the adjusted poses (RetriangulateTracks): those of the input model were built
// at its poses, and on a weakly constrained drive the partition of the observations into tracks
// moves cam_from_lidar by several sigma. True if any track changed, so that the joint runs again.
bool RebuildTracks(const std::string& database_path, colmap::Reconstruction* reconstruction) {
  const colmap::Reconstruction adjusted = *reconstruction;
  RetriangulateTracks(database_path, reconstruction);
  const double retracked = FractionOfObservationsRetracked(adjusted, *reconstruction);
  std::ostringstream line;  // std::cout may hold a fixed precision of 1
  line << "Tracks rebuilt at the adjusted poses: " << reconstruction->NumPoints3D()
       << " landmarks; " << 100 * retracked << " % of the observations changed track"
       << (retracked > 0 ? "; the joint adjuster runs again on them" : "");
  std::cout << line.str() << std::endl;
  return retracked > 0;
}

// The joint adjustment, then once more on the tracks rebuilt at its poses if any changed.
JointAdjustmentSummary AdjustWithRebuiltTracks(const JointAdjusterOptions& options,
                                               const JointProblemData& data,
                                               const std::string& database_path,
                                               colmap::Reconstruction* reconstruction,
                                               colmap::Rigid3d* cam_from_lidar) {
  const JointAdjuster adjuster(options);
  const JointAdjustmentSummary summary = adjuster.Run(data, reconstruction, cam_from_lidar);
  if (!RebuildTracks(database_path, reconstruction)) return summary;
  return adjuster.Run(data, reconstruction, cam_from_lidar);
}

}  // namespace

bool JointAdjusterStepOptions::Check() const { return adjuster.Check() && data.Check(); }

void RunJointAdjusterStep(const StationDataset& dataset,
                          const JointAdjusterPaths& paths,
                          JointAdjusterStepOptions options) {
  THROW_CHECK(options.Check());
  const std::string mode = ChoiceName(kJointModeNames, options.adjuster.mode);
  options.adjuster.sigma_lidar_m = dataset.rig.LidarRangeNoiseM();
  if (!dataset.rig.IsStereo() && options.adjuster.mode == JointMode::kStereoOnly) {
    throw std::invalid_argument("--mode stereo_only needs a stereo rig; " + dataset.root +
                                "/rig.json has one camera");
  }
  const auto start = std::chrono::steady_clock::now();
  colmap::Reconstruction reconstruction = ReadInputModel(paths.input_path);
  const CaptureProfile profile =
      options.profile ? *options.profile : InputCaptureProfile(dataset, paths.input_path);
  const bool vertical_alignment =
      DecideFromMotion(dataset, profile, reconstruction, &options.adjuster);
  colmap::Rigid3d cam_from_lidar =
      InitialCamFromLidar(paths.cam_from_lidar_path, paths.input_path, dataset);
  const colmap::Rigid3d initial = cam_from_lidar;
  std::cout << "Joint adjuster (" << mode << "): " << reconstruction.NumRegImages() << " images, "
            << reconstruction.NumPoints3D() << " landmarks" << std::endl;
  const std::unique_ptr<LoadedJointData> loaded =
      LoadJointProblemData(paths.database_path,
                           dataset,
                           reconstruction,
                           cam_from_lidar,
                           options.adjuster.mode != JointMode::kStereoOnly,
                           options.data);
  std::cout << "Loaded depth priors, clouds and the pose graph (" << SecondsSince(start) << " s)"
            << std::endl;
  DecideTimeOffset(dataset, profile, loaded.get(), &options);
  if (options.use_guess && !dataset.rig.cam_from_lidar_guess_sigma) {
    loaded->data.cam_from_lidar_guess = dataset.rig.cam_from_lidar_guess;
  }
  const std::optional<VerticalAlignment> vertical = AddExtrinsicMeasurements(
      dataset, vertical_alignment, reconstruction, options, loaded.get(), &cam_from_lidar);
  const JointAdjustmentSummary summary = AdjustWithRebuiltTracks(
      options.adjuster, loaded->data, paths.database_path, &reconstruction, &cam_from_lidar);

  PartialOutputFolder partial(paths.output_path);
  reconstruction.WriteBinary(partial.Path());
  if (options.write_text) reconstruction.WriteText(partial.Path());
  WritePoseFile(
      partial.File("cam_from_lidar.txt"),
      "cam_from_lidar refined by colmap-lidar joint_adjuster (" + mode + "); qw qx qy qz tx ty tz",
      cam_from_lidar);
  Trajectory cameras = ModelCameraTrajectory(reconstruction);
  AttachStationTimes(dataset.stations, dataset.frame_times, &cameras);
  WriteTrajectoryExports(partial.File("camera_poses"), cameras);
  const std::string caveat = UncertaintyCaveat(summary.motion, profile.IsMovingPlatform());
  WriteJointReport(partial.Path(),
                   options.adjuster,
                   *loaded,
                   {initial, cam_from_lidar, summary, caveat, vertical});
  WriteJointPlots(partial.Path(), summary, vertical);
  partial.Commit();
  PrintJointUncertainty(summary, caveat);
  PrintWarnings(CheckStartDeparture(initial, cam_from_lidar, loaded->data, summary),
                CheckAssociationSettling(summary));
  std::cout << "Wrote " << paths.output_path << " (" << SecondsSince(start) << " s)" << std::endl;
}

}  // namespace colmap_lidar
