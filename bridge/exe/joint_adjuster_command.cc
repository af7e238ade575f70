// colmap-lidar joint_adjuster: the joint problem on a COLMAP sparse model
// (bridge/joint/joint_adjuster.h).
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "bridge/exe/vertical_alignment_step.h"
#include "bridge/initialization/lidar_registration_files.h"
#include "bridge/joint/association_settling.h"
#include "bridge/joint/joint_adjuster.h"
#include "bridge/joint/joint_problem_data.h"
#include "bridge/joint/start_departure.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/plot.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/scene/reconstruction.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// cam_from_lidar's axes in report order: rotation about, then translation along the camera axes.
constexpr const char* kExtrinsicAxes[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};

std::array<bool, 3> ParseHeldAxes(const std::string& text) {
  std::array<bool, 3> held = {false, false, false};
  std::stringstream stream(text);
  std::string axis;
  while (std::getline(stream, axis, ',')) {
    if (axis == "x") {
      held[0] = true;
    } else if (axis == "y") {
      held[1] = true;
    } else if (axis == "z") {
      held[2] = true;
    } else if (!axis.empty()) {
      throw std::invalid_argument("--hold_translation: unknown axis '" + axis +
                                  "' (a comma-separated subset of x,y,z)");
    }
  }
  return held;
}

nlohmann::json TermJson(const TermStats& term) {
  return {{"observations", term.num_observations},
          {"outliers", term.num_outliers},
          {"cost_before", term.cost_before},
          {"cost_after", term.cost_after}};
}

nlohmann::json PoseJson(const colmap::Rigid3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation;
  return {{"qw", q.w()},
          {"qx", q.x()},
          {"qy", q.y()},
          {"qz", q.z()},
          {"tx", pose.translation.x()},
          {"ty", pose.translation.y()},
          {"tz", pose.translation.z()}};
}

// The measurement of T_e that joined the cost, and how far the result lies from it in its own
// sigmas (the Mahalanobis distance of the rotation vector and translation difference).
nlohmann::json MeasurementJson(const ExtrinsicMeasurement& measurement,
                               const colmap::Rigid3d& refined) {
  const Eigen::AngleAxisd rotation(refined.rotation *
                                   measurement.cam_from_lidar.rotation.inverse());
  Eigen::Matrix<double, 6, 1> difference;
  difference << rotation.angle() * rotation.axis(),
      refined.translation - measurement.cam_from_lidar.translation;
  const Eigen::Matrix<double, 6, 1> sigmas = measurement.covariance.diagonal().cwiseSqrt();
  return {{"source", measurement.source},
          {"prior", measurement.prior},
          {"cam_from_lidar", PoseJson(measurement.cam_from_lidar)},
          {"sigma_rotation_deg_in_cam",
           {sigmas(0) * 180 / M_PI, sigmas(1) * 180 / M_PI, sigmas(2) * 180 / M_PI}},
          {"sigma_translation_mm_in_cam", {1000 * sigmas(3), 1000 * sigmas(4), 1000 * sigmas(5)}},
          {"result_mahalanobis_distance",
           std::sqrt(difference.dot(measurement.covariance.ldlt().solve(difference)))}};
}

// Per solve: the terms' costs and outliers, the depth priors' outlier rules, iterations and time.
nlohmann::json SolvesJson(const std::vector<SolveStats>& stats) {
  nlohmann::json solves = nlohmann::json::array();
  for (const SolveStats& solve : stats) {
    solves.push_back({{"round", solve.round},
                      {"outlier_iteration", solve.outlier_iteration},
                      {"reprojection", TermJson(solve.reprojection)},
                      {"depth", TermJson(solve.depth)},
                      {"lidar", TermJson(solve.lidar)},
                      {"landmark_lidar", TermJson(solve.landmark_lidar)},
                      {"depth_outliers",
                       {{"residual_scale", solve.depth_outliers.residual_scale},
                        {"beyond_sigma", solve.depth_outliers.beyond_sigma},
                        {"beyond_absolute", solve.depth_outliers.beyond_absolute},
                        {"restored", solve.depth_outliers.restored}}},
                      {"iterations", solve.num_iterations},
                      {"termination", solve.termination},
                      {"seconds", solve.seconds}});
  }
  return solves;
}

nlohmann::json MeasurementsJson(const std::vector<ExtrinsicMeasurement>& measurements,
                                const colmap::Rigid3d& refined) {
  nlohmann::json json = nlohmann::json::array();
  for (const ExtrinsicMeasurement& measurement : measurements) {
    json.push_back(MeasurementJson(measurement, refined));
  }
  return json;
}

nlohmann::json MatrixJson(const Eigen::MatrixXd& matrix) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < matrix.rows(); ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < matrix.cols(); ++c) row.push_back(matrix(r, c));
    rows.push_back(row);
  }
  return rows;
}

// Names of the axes held at their start (no sigma).
std::vector<std::string> UndeterminedAxes(const ExtrinsicUncertainty& u) {
  std::vector<std::string> axes;
  for (int k = 0; k < 6; ++k) {
    if (u.undetermined[k]) axes.push_back(kExtrinsicAxes[k]);
  }
  return axes;
}

// Axes whose reported sigma is at least 1/sqrt(2) of a prior's: the data know them no better than
// the prior does (posterior variance 1 / (1/data + 1/prior) >= prior / 2 <=> data >= prior).
std::vector<std::string> PriorDeterminedAxes(
    const ExtrinsicUncertainty& u, const std::vector<ExtrinsicMeasurement>& measurements) {
  std::vector<std::string> axes;
  if (!u.computed) return axes;
  for (const ExtrinsicMeasurement& measurement : measurements) {
    if (!measurement.prior) continue;
    for (int k = 0; k < 6; ++k) {
      const double prior_variance =
          measurement.covariance(k, k) * std::pow(k < 3 ? 180 / M_PI : 1000.0, 2);
      if (u.covariance(k, k) >= 0.5 * prior_variance) axes.push_back(kExtrinsicAxes[k]);
    }
  }
  return axes;
}

// report.json's "uncertainty": the cluster-robust and formal covariances of cam_from_lidar.
// `caveat`: UncertaintyCaveat's sentence (empty: validated for this kind of capture).
nlohmann::json UncertaintyJson(const ExtrinsicUncertainty& u,
                               const ObservabilityOptions& observability,
                               const std::string& caveat) {
  nlohmann::json uncertainty = {{"computed", u.computed}, {"message", u.message}};
  uncertainty["validated_by_coverage"] = caveat.empty();
  if (!caveat.empty()) uncertainty["caveat"] = caveat;
  if (u.computed) {
    uncertainty["variance_factor"] = u.variance_factor;
    uncertainty["covariance_deg_mm"] = MatrixJson(u.covariance);
    uncertainty["cluster_robust"] = u.cluster_robust;
    uncertainty["stereo_scale_sigma"] = observability.stereo_scale_sigma;
    uncertainty["stereo_scale_sensitivity_deg_mm"] =
        MatrixJson(u.stereo_scale_sensitivity.transpose());
    uncertainty["num_clusters"] = u.num_clusters;
    uncertainty["formal_covariance_deg_mm"] = MatrixJson(u.formal_covariance);
    const Eigen::VectorXd formal_sigma = u.formal_covariance.diagonal().cwiseSqrt();
    uncertainty["formal_sigma_rotation_deg"] = {formal_sigma[0], formal_sigma[1], formal_sigma[2]};
    uncertainty["formal_sigma_translation_mm"] = {
        formal_sigma[3], formal_sigma[4], formal_sigma[5]};
    // Axes held at their start have no sigma (null).
    const Eigen::VectorXd sigma = u.covariance.diagonal().cwiseSqrt();
    nlohmann::json sigmas = nlohmann::json::array();
    for (int k = 0; k < 6; ++k) {
      sigmas.push_back(u.undetermined[k] ? nlohmann::json(nullptr) : nlohmann::json(sigma[k]));
    }
    uncertainty["sigma_deg_mm"] = sigmas;
    uncertainty["sigma_rotation_deg"] = {sigmas[0], sigmas[1], sigmas[2]};
    uncertainty["sigma_translation_mm"] = {sigmas[3], sigmas[4], sigmas[5]};
    uncertainty["undetermined_axes"] = UndeterminedAxes(u);
    uncertainty["eigen_std_devs"] = MatrixJson(u.eigenvalues.transpose());
    uncertainty["eigenvectors_columns"] = MatrixJson(u.eigenvectors);
  }
  return uncertainty;
}

// Each data group's estimated sigma in units of its nominal one (sqrt of the factor in force), and
// the last estimate's observations, redundancy and factor.
nlohmann::json VarianceComponentsJson(const JointAdjusterOptions& options,
                                      const JointAdjustmentSummary& summary) {
  nlohmann::json json = {{"estimated", options.estimate_variance_components}};
  const VarianceFactors& f = summary.variance_factors;
  json["sigma_over_nominal"] = {{"reprojection", std::sqrt(f.reprojection)},
                                {"depth_prior", std::sqrt(f.depth)},
                                {"lidar", std::sqrt(f.lidar)},
                                {"landmark_lidar", std::sqrt(f.landmark_lidar)}};
  json["sigma_lidar_m"] = options.sigma_lidar_m * std::sqrt(f.lidar / options.lidar_weight);
  nlohmann::json groups = nlohmann::json::array();
  for (const VarianceComponent& c : summary.variance_components) {
    groups.push_back({{"group", c.name},
                      {"observations", c.num_observations},
                      {"parameter_share", c.parameter_share},
                      {"redundancy", c.redundancy},
                      {"last_factor", c.factor}});
  }
  json["groups"] = groups;
  return json;
}

nlohmann::json MotionJson(const MotionAnalysis& motion) {
  return {{"stations", motion.num_stations},
          {"rotating_pairs", motion.num_rotating_pairs},
          {"max_axis_angle_deg", motion.max_axis_angle_deg},
          {"second_axis_rotation_deg", motion.second_axis_rotation_deg},
          {"unique", motion.unique},
          {"verdict", motion.verdict}};
}

// NaN (an axis without a sigma) as null.
nlohmann::json SigmasJson(const std::array<double, 6>& values) {
  nlohmann::json json = nlohmann::json::array();
  for (const double v : values)
    json.push_back(std::isnan(v) ? nlohmann::json() : nlohmann::json(v));
  return json;
}

nlohmann::json AssociationSettlingJson(const AssociationSettling& settling) {
  return {{"settled", settling.settled},
          {"rounds", settling.rounds},
          {"last_round_move_deg_mm", settling.last_move},
          {"last_round_move_sigmas", SigmasJson(settling.last_move_sigmas)},
          {"warnings", settling.warnings}};
}

nlohmann::json StartDepartureJson(const StartDeparture& departure) {
  return {{"move_deg_mm", departure.move},
          {"allowed_deg_mm", departure.allowed},
          {"warnings", departure.warnings}};
}

// One sentence on what the adjustment could determine of cam_from_lidar.
std::string ObservabilityVerdict(const JointAdjusterOptions& options,
                                 const JointAdjustmentSummary& summary) {
  const ExtrinsicUncertainty& u = summary.uncertainty;
  if (options.mode != JointMode::kJoint) {
    return "cam_from_lidar held constant (" + JointModeName(options.mode) + ")";
  }
  if (u.unobservable.empty() && summary.motion.unique) return "cam_from_lidar is observable";
  // A degenerate motion whose directions the data observe all the same (a car through the
  // landmark-to-LiDAR-plane term): say both, not "unobservable" against the uncertainty.
  if (!u.unobservable.empty()) return u.unobservable.front();
  return "cam_from_lidar is observable by its uncertainty" +
         std::string(options.landmark_lidar_weight > 0 ? " (with the landmark-to-LiDAR-plane term)"
                                                       : "") +
         ", though the motion alone is degenerate: " + summary.motion.verdict;
}

// What one joint adjustment ended with, for its report.
struct JointOutcome {
  const colmap::Rigid3d& initial;  // cam_from_lidar at the start
  const colmap::Rigid3d& refined;
  const JointAdjustmentSummary& summary;
  const std::string& caveat;  // UncertaintyCaveat
  const std::optional<VerticalAlignment>& vertical;
};

void WriteReport(const std::string& directory,
                 const JointAdjusterOptions& options,
                 const LoadedJointData& loaded,
                 const JointOutcome& outcome) {
  const colmap::Rigid3d& initial = outcome.initial;
  const colmap::Rigid3d& refined = outcome.refined;
  const JointAdjustmentSummary& summary = outcome.summary;
  const std::string& caveat = outcome.caveat;
  const std::optional<VerticalAlignment>& vertical = outcome.vertical;
  nlohmann::json report;
  if (vertical) report["vertical_alignment"] = VerticalAlignmentJson(*vertical);
  report["mode"] = JointModeName(options.mode);
  report["conventions"] =
      "cam_from_lidar maps LiDAR points into the left camera; quaternions w "
      "first; covariance over (rotation vector about the camera axes [deg], "
      "translation [mm])";
  report["cam_from_lidar_initial"] = PoseJson(initial);
  report["cam_from_lidar"] = PoseJson(refined);
  report["pose_graph"] = {{"image_pairs", loaded.num_image_pairs},
                          {"lidar_pairs", loaded.num_lidar_pairs},
                          {"pairs", loaded.data.pairs.size()}};
  report["solves"] = SolvesJson(summary.solves);
  report["final_problem"] = {{"reprojection_residuals", summary.final_reprojection_residuals},
                             {"depth_residuals", summary.final_depth_residuals},
                             {"lidar_residuals", summary.final_lidar_residuals},
                             {"landmark_lidar_residuals", summary.final_landmark_lidar_residuals}};
  report["landmark_lidar_weight"] = options.landmark_lidar_weight;
  report["variance_components"] = VarianceComponentsJson(options, summary);
  if (summary.time_offset) {
    report["time_offset"] = {{"lidar_minus_camera", *summary.time_offset},
                             {"unit", loaded.data.image_times.empty() ? "frames" : "s"}};
  }
  report["extrinsic_measurements"] = MeasurementsJson(loaded.data.extrinsic_measurements, refined);
  report["start_departure"] =
      StartDepartureJson(CheckStartDeparture(initial, refined, loaded.data, summary));
  report["association"] = AssociationSettlingJson(CheckAssociationSettling(summary));
  if (!summary.lidar_free_axis_in_cam.isZero()) {
    const Eigen::Vector3d& axis = summary.lidar_free_axis_in_cam;
    report["lidar_free_rotation"] = {{"axis_in_cam", {axis.x(), axis.y(), axis.z()}},
                                     {"lidar_term_angle_deg", summary.lidar_free_angle_deg}};
  }
  const ExtrinsicUncertainty& u = summary.uncertainty;
  report["uncertainty"] = UncertaintyJson(u, options.observability, caveat);
  report["uncertainty"]["prior_determined_axes"] =
      PriorDeterminedAxes(u, loaded.data.extrinsic_measurements);
  report["unobservable"] = u.unobservable;
  report["held_at_initial"] = summary.held_at_initial;
  report["hold_thresholds"] = {{"enabled", options.hold_unobservable},
                               {"rotation_deg", options.hold_rotation_deg},
                               {"translation_mm", options.hold_translation_mm}};
  report["motion"] = MotionJson(summary.motion);
  report["observability_verdict"] = ObservabilityVerdict(options, summary);
  nlohmann::json curves = nlohmann::json::array();
  for (const PerturbationCurve& curve : summary.perturbation) {
    curves.push_back(
        {{"parameter", curve.parameter}, {"offsets", curve.offsets}, {"costs", curve.costs}});
  }
  report["perturbation"] = curves;
  WriteFileAtomically(directory + "/report.json", report.dump(2) + "\n");
}

void WritePlots(const std::string& directory,
                const JointAdjustmentSummary& summary,
                const std::optional<VerticalAlignment>& vertical) {
  if (vertical && vertical->valid) {
    WriteVerticalAlignmentPlot((fs::path(directory) / "vertical_alignment.png").string(),
                               *vertical);
  }
  PlotSeries total{"total cost", {}, {}};
  for (size_t k = 0; k < summary.solves.size(); ++k) {
    const SolveStats& s = summary.solves[k];
    total.x.push_back(static_cast<double>(k + 1));
    total.y.push_back(s.reprojection.cost_after + s.depth.cost_after + s.lidar.cost_after +
                      s.landmark_lidar.cost_after);
  }
  LinePlotOptions cost_options;
  cost_options.title = "Joint problem: cost after each solve";
  cost_options.x_label = "solve (rounds x outlier iterations)";
  cost_options.y_label = "cost";
  cost_options.log_y = true;
  WriteLinePlotPng(directory + "/cost.png", {total}, cost_options);
  if (summary.perturbation.empty()) return;

  std::ostringstream csv;
  csv << "# total cost with one cam_from_lidar parameter perturbed around the "
         "optimum (x y z in mm, roll pitch yaw in deg about the camera axes)\n"
      << "parameter,offset,cost\n";
  std::vector<PlotSeries> translation, rotation;
  for (const PerturbationCurve& curve : summary.perturbation) {
    PlotSeries series{curve.parameter, curve.offsets, curve.costs};
    (curve.parameter.size() == 1 ? translation : rotation).push_back(series);
    for (size_t k = 0; k < curve.offsets.size(); ++k) {
      csv << curve.parameter << "," << curve.offsets[k] << "," << std::setprecision(10)
          << curve.costs[k] << "\n";
    }
  }
  WriteFileAtomically(directory + "/perturbation.csv", csv.str());
  LinePlotOptions plot;
  plot.title = "Cost vs cam_from_lidar translation offset";
  plot.x_label = "offset [mm]";
  plot.y_label = "total cost";
  WriteLinePlotPng(directory + "/perturbation_translation.png", translation, plot);
  plot.title = "Cost vs cam_from_lidar rotation offset";
  plot.x_label = "offset [deg]";
  WriteLinePlotPng(directory + "/perturbation_rotation.png", rotation, plot);
}

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

void PrintUncertainty(const JointAdjustmentSummary& summary, const std::string& caveat) {
  std::cout << "Motion: " << summary.motion.verdict << std::endl;
  if (summary.uncertainty.computed) {
    const Eigen::VectorXd sigma = summary.uncertainty.covariance.diagonal().cwiseSqrt();
    std::ostringstream line;
    line << std::setprecision(3) << "cam_from_lidar sigma (deg about, mm along the camera axes):";
    for (int k = 0; k < 6; ++k) {
      line << " " << kExtrinsicAxes[k] << " ";
      if (summary.uncertainty.undetermined[k]) {
        line << "undetermined";
      } else {
        line << sigma[k];
      }
    }
    std::cout << line.str() << std::endl;
    if (!caveat.empty()) std::cout << "cam_from_lidar sigma " << caveat << std::endl;
  }
  for (const std::string& sentence : summary.uncertainty.unobservable) {
    std::cout << "UNOBSERVABLE: " << sentence << std::endl;
  }
  for (const std::string& direction : summary.held_at_initial) {
    std::cout << "HELD at the initial value: " << direction << std::endl;
  }
}

}  // namespace

bool JointAdjusterStepOptions::Check() const { return AdjusterOptions().Check() && data.Check(); }

JointAdjusterOptions JointAdjusterStepOptions::AdjusterOptions() const {
  JointAdjusterOptions resolved = adjuster;
  resolved.mode = JointModeFromName(mode);
  resolved.hold_translation = ParseHeldAxes(hold_translation);
  return resolved;
}

void AddJointAdjusterOptions(const std::string& prefix,
                             colmap::OptionManager* manager,
                             JointAdjusterStepOptions* options) {
  PrefixedOptions add(manager, prefix);
  JointAdjusterOptions& adjuster = options->adjuster;
  add.Add("estimate_variance_components",
          &adjuster.estimate_variance_components,
          "weight each data group by its variance factor estimated with the solve");
  add.Add("estimate_time_offset",
          &options->estimate_time_offset,
          "on a moving platform, estimate the LiDAR clock's offset from the cameras");
  add.Add("hold_rotation", &adjuster.hold_rotation, "hold cam_from_lidar's rotation at its start");
  add.Add("hold_translation",
          &options->hold_translation,
          "camera axes of cam_from_lidar's translation held at their start, e.g. y or x,z");
  add.Add("hold_rotation_deg",
          &adjuster.hold_rotation_deg,
          "sigma above which a rotation direction is held at its start and named undetermined");
  add.Add("hold_translation_mm",
          &adjuster.hold_translation_mm,
          "sigma above which a translation direction is held at its start and named undetermined");
  add.Add("write_text", &options->write_text, "also write cameras.txt, images.txt, points3D.txt");
}

namespace {

// Options joint_adjuster no longer takes, with what decides their value now.
struct RemovedOption {
  const char* name;
  const char* replacement;
};

constexpr char kWeightsEstimated[] =
    "each data group's weight is estimated with the solve (variance components)";
constexpr char kGatesFixed[] = "the outlier gates are fixed (docs/joint_adjuster.md lists them)";
constexpr char kNoLoss[] =
    "no robust loss: the outlier gates remove outliers (docs/joint_adjuster.md)";
constexpr char kRoundsFixed[] =
    "the association rounds run until cam_from_lidar stops moving, at most 10; report.json "
    "'association' says whether they settled (docs/joint_adjuster.md)";
constexpr char kSamplingFixed[] =
    "the LiDAR association's sampling is fixed (docs/joint_adjuster.md)";
constexpr char kCovarianceFixed[] =
    "the covariance model is fixed (docs/joint_adjuster.md, Uncertainty)";
constexpr char kFromMotion[] = "decided from the stations' motion (docs/joint_adjuster.md)";

constexpr RemovedOption kRemovedOptions[] = {
    {"depth_weight", kWeightsEstimated},
    {"lidar_weight", kWeightsEstimated},
    {"landmark_lidar_weight", kFromMotion},
    {"sigma_landmark_lidar_m", kWeightsEstimated},
    {"loss", kNoLoss},
    {"loss_scale", kNoLoss},
    {"max_reprojection_error_px", kGatesFixed},
    {"max_depth_error_sigmas", kGatesFixed},
    {"depth_gate_from_residual_scale", kGatesFixed},
    {"max_depth_error_m", kGatesFixed},
    {"max_point_to_plane_m", kGatesFixed},
    {"max_landmark_plane_m", kGatesFixed},
    {"max_landmark_plane_sigmas", kGatesFixed},
    {"association_max_curvature", kGatesFixed},
    {"max_outlier_iterations", kGatesFixed},
    {"first_depth_prior_round", kRoundsFixed},
    {"num_association_rounds", kRoundsFixed},
    {"max_association_rounds", kRoundsFixed},
    {"round_convergence_deg", kRoundsFixed},
    {"round_convergence_mm", kRoundsFixed},
    {"initial_association_distance_m", kGatesFixed},
    {"association_max_distance_m", kGatesFixed},
    {"max_num_iterations", "each solve runs up to Ceres' fixed iteration limit (100)"},
    {"num_samples_per_pair", kSamplingFixed},
    {"normal_space_sampling", kSamplingFixed},
    {"max_lidar_neighbors", kSamplingFixed},
    {"min_image_pair_inliers", kSamplingFixed},
    {"compress_lidar_blocks", "the LiDAR term is always passed to Ceres in its compressed form"},
    {"free_lidar_drive_roll", "the LiDAR term and the others share one cam_from_lidar"},
    {"extrinsic_prior_sigma_m",
     "a prior on cam_from_lidar comes only from rig.json's cam_from_lidar_guess_sigma"},
    {"hold_unobservable",
     "undetermined directions are always held at their start and named (hold_rotation_deg, "
     "hold_translation_mm)"},
    {"stereo_scale_sigma", kCovarianceFixed},
    {"two_way_lidar_clusters", kCovarianceFixed},
    {"unobservable_translation_mm", kCovarianceFixed},
    {"unobservable_rotation_deg", kCovarianceFixed},
    {"use_stereo_alignment",
     "the stereo-LiDAR alignment is the start, not a measurement in the cost"},
    {"vertical_alignment", kFromMotion},
    {"sigma_lidar_m",
     "the LiDAR's range noise is rig.json's lidar.range_noise_m (default 0.02 m), the starting "
     "weight of E_l that the estimated variance factor scales"},
};

}  // namespace

namespace {

// The option keys of a COLMAP project file (boost's ini syntax): "key = value" lines, a key under a
// "[Section]" header named "Section.key".
std::vector<std::string> ProjectFileKeys(const std::string& path) {
  std::ifstream file(path);
  if (path.empty()) throw std::invalid_argument("--project_path needs a file");
  if (!file) throw std::invalid_argument("cannot read the project file " + path);
  std::vector<std::string> keys;
  std::string section;
  for (std::string line; std::getline(file, line);) {
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    if (line[first] == '[') {
      section = line.substr(first + 1, line.find(']') - first - 1) + ".";
      continue;
    }
    const std::string key = line.substr(first, line.find('=') - first);
    keys.push_back(section + key.substr(0, key.find_last_not_of(" \t") + 1));
  }
  return keys;
}

// The removed option `key` names (with `prefix`), or null.
const RemovedOption* FindRemovedOption(const std::string& key, const std::string& prefix) {
  for (const RemovedOption& removed : kRemovedOptions) {
    if (key == prefix + removed.name) return &removed;
  }
  return nullptr;
}

}  // namespace

void RefuseRemovedJointAdjusterOptions(int argc, char** argv, const std::string& prefix) {
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument.rfind("--", 0) != 0) continue;
    const std::string key = argument.substr(2, argument.find('=') - 2);
    if (const RemovedOption* removed = FindRemovedOption(key, prefix)) {
      throw std::invalid_argument("--" + key + " is no longer an option: " + removed->replacement);
    }
    if (key != "project_path") continue;
    const std::string path = argument.find('=') != std::string::npos
                                 ? argument.substr(argument.find('=') + 1)
                                 : (i + 1 < argc ? argv[i + 1] : "");
    for (const std::string& file_key : ProjectFileKeys(path)) {
      if (const RemovedOption* removed = FindRemovedOption(file_key, prefix)) {
        throw std::invalid_argument(path + ": " + file_key +
                                    " is no longer an option: " + removed->replacement);
      }
    }
  }
}

namespace {

// What pose_initializer wrote about its start (INPUT/initialization.json), if anything.
struct InitialisationFacts {
  bool one_axis = false;  // every rotation about one axis (a driving platform)
};

// A model without one (e.g. the user's own) has no facts; an unreadable one is an error naming it.
InitialisationFacts ReadInitialisationFacts(const std::string& input_path) {
  InitialisationFacts facts;
  const fs::path path = fs::path(input_path) / "initialization.json";
  if (!fs::exists(path)) return facts;
  std::ifstream file(path);
  const nlohmann::json init = nlohmann::json::parse(file, nullptr, /*allow_exceptions=*/false);
  if (!file || init.is_discarded() || !init.is_object()) {
    throw std::runtime_error("cannot read " + path.string() + " (pose_initializer's report)");
  }
  facts.one_axis = init.contains("hand_eye") &&
                   init["hand_eye"].contains("unobservable_translation_axis_in_cam");
  return facts;
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

// A moving platform: rig.json's clouds are sweeps, or initialization.json reports a one-axis
// hand-eye.
bool IsMovingPlatform(const StationDataset& dataset, const InitialisationFacts& facts) {
  return dataset.rig.IsMovingPlatform() || facts.one_axis;
}

// Decided from the motion (DecideFromMotion). E_m: on for a monocular rig, and for a stereo rig on
// a moving platform (rig.json's clouds are sweeps, or initialization.json's one-axis hand-eye) whose
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
                      const InitialisationFacts& facts,
                      const colmap::Reconstruction& reconstruction,
                      JointAdjusterOptions* adjuster) {
  const MotionAnalysis motion = AnalyseMotion(reconstruction, adjuster->observability);
  const bool degenerate_motion =
      facts.one_axis || (!motion.unique && dataset.rig.IsMovingPlatform());
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
                      const InitialisationFacts& facts,
                      LoadedJointData* loaded,
                      JointAdjusterStepOptions* options) {
  options->adjuster.estimate_time_offset =
      options->estimate_time_offset && IsMovingPlatform(dataset, facts);
  if (options->adjuster.estimate_time_offset) {
    loaded->data.image_times = ImageTimes(dataset, *loaded);
  }
}

}  // namespace

void RunJointAdjusterStep(const StationDataset& dataset,
                          const JointAdjusterPaths& paths,
                          JointAdjusterStepOptions options) {
  THROW_CHECK(options.Check());
  options.adjuster = options.AdjusterOptions();
  options.adjuster.sigma_lidar_m = dataset.rig.LidarRangeNoiseM();
  if (!dataset.rig.IsStereo() && options.adjuster.mode == JointMode::kStereoOnly) {
    throw std::invalid_argument("--mode stereo_only needs a stereo rig; " + dataset.root +
                                "/rig.json has one camera");
  }
  const auto start = std::chrono::steady_clock::now();
  colmap::Reconstruction reconstruction = ReadInputModel(paths.input_path);
  const InitialisationFacts facts = ReadInitialisationFacts(paths.input_path);
  const bool vertical_alignment =
      DecideFromMotion(dataset, facts, reconstruction, &options.adjuster);
  colmap::Rigid3d cam_from_lidar =
      InitialCamFromLidar(paths.cam_from_lidar_path, paths.input_path, dataset);
  const colmap::Rigid3d initial = cam_from_lidar;
  std::cout << "Joint adjuster (" << options.mode << "): " << reconstruction.NumRegImages()
            << " images, " << reconstruction.NumPoints3D() << " landmarks" << std::endl;
  const std::unique_ptr<LoadedJointData> loaded =
      LoadJointProblemData(paths.database_path,
                           dataset,
                           reconstruction,
                           cam_from_lidar,
                           options.adjuster.mode != JointMode::kStereoOnly,
                           options.data);
  std::cout << "Loaded depth priors, clouds and the pose graph (" << SecondsSince(start) << " s)"
            << std::endl;
  DecideTimeOffset(dataset, facts, loaded.get(), &options);
  const std::optional<VerticalAlignment> vertical = AddExtrinsicMeasurements(
      dataset, vertical_alignment, reconstruction, options, loaded.get(), &cam_from_lidar);
  const JointAdjustmentSummary summary =
      JointAdjuster(options.adjuster).Run(loaded->data, &reconstruction, &cam_from_lidar);

  PartialOutputFolder partial(paths.output_path);
  reconstruction.WriteBinary(partial.Path());
  if (options.write_text) reconstruction.WriteText(partial.Path());
  WritePoseFile(partial.File("cam_from_lidar.txt"),
                "cam_from_lidar refined by colmap-lidar joint_adjuster (" + options.mode +
                    "); qw qx qy qz tx ty tz",
                cam_from_lidar);
  Trajectory cameras = ModelCameraTrajectory(reconstruction);
  AttachStationTimes(dataset.stations, dataset.frame_times, &cameras);
  WriteTrajectoryExports(partial.File("camera_poses"), cameras);
  const std::string caveat = UncertaintyCaveat(summary.motion, IsMovingPlatform(dataset, facts));
  WriteReport(partial.Path(),
              options.adjuster,
              *loaded,
              {initial, cam_from_lidar, summary, caveat, vertical});
  WritePlots(partial.Path(), summary, vertical);
  partial.Commit();
  PrintUncertainty(summary, caveat);
  PrintWarnings(CheckStartDeparture(initial, cam_from_lidar, loaded->data, summary),
                CheckAssociationSettling(summary));
  std::cout << "Wrote " << paths.output_path << " (" << SecondsSince(start) << " s)" << std::endl;
}

int RunJointAdjuster(int argc, char** argv) {
  std::string dataset_path, registration_path;
  JointAdjusterPaths paths;
  JointAdjusterStepOptions joint;
  colmap::OptionManager options;
  options.AddDatabaseOptions();
  options.AddRequiredOption("input_path", &paths.input_path);
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddRequiredOption("output_path", &paths.output_path);
  options.AddDefaultOption("mode", &joint.mode, "joint | precalibrated | stereo_only");
  options.AddDefaultOption("cam_from_lidar",
                           &paths.cam_from_lidar_path,
                           "qw qx qy qz tx ty tz file; default: INPUT/cam_from_lidar.txt, else "
                           "rig.json's cam_from_lidar_guess");
  options.AddDefaultOption("registration_path", &registration_path, kRegistrationPathHelp);
  AddJointAdjusterOptions("", &options, &joint);
  RefuseRemovedJointAdjusterOptions(argc, argv, "");
  options.Parse(argc, argv);
  THROW_CHECK(joint.Check());  // before any file is read
  paths.database_path = *options.database_path;
  RunJointAdjusterStep(
      WithRegistratorClouds(ReadStationDataset(dataset_path), registration_path), paths, joint);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
