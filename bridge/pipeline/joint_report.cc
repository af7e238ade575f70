#include "bridge/pipeline/joint_report.h"

#include "bridge/joint/association_settling.h"
#include "bridge/joint/start_departure.h"
#include "bridge/pipeline/vertical_alignment_step.h"
#include "colmap_ext/logging.h"
#include "lidar/plot.h"
#include "lidar/util/atomic_file.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// cam_from_lidar's axes in report order: rotation about, then translation along the camera axes.
constexpr const char* kExtrinsicAxes[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};

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
                      {"invalid_steps", solve.invalid_steps},
                      {"observations_at_camera_centres", solve.observations_at_camera_centres},
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

// Each data term's pull on cam_from_lidar, in deg / mm and in sigmas.
nlohmann::json TermPullsJson(const std::vector<TermPull>& pulls) {
  nlohmann::json json = nlohmann::json::array();
  for (const TermPull& pull : pulls) {
    json.push_back({{"term", pull.term},
                    {"pull_deg_mm", MatrixJson(pull.pull.transpose())},
                    {"pull_sigmas", MatrixJson(pull.pull_sigmas.transpose())},
                    {"significance", MatrixJson(pull.significance.transpose())}});
  }
  return json;
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
    uncertainty["disparity_bias_sigma_px"] = observability.disparity_bias_sigma_px;
    uncertainty["disparity_bias_sensitivity_deg_mm"] =
        MatrixJson(u.disparity_bias_sensitivity.transpose());
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
    uncertainty["term_pulls"] = TermPullsJson(u.term_pulls);
    uncertainty["term_disagreements"] = u.term_disagreements;
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

// E_m's associations per camera axis their surface faces, in mm.
nlohmann::json LandmarkFacingJson(const std::array<LandmarkPlaneFacing, 3>& facing) {
  nlohmann::json json;
  const char* const axes[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    json[axes[axis]] = {{"observations", facing[axis].num_observations},
                        {"mean_residual_mm", 1000 * facing[axis].mean_residual_m},
                        {"rms_residual_mm", 1000 * facing[axis].rms_residual_m}};
  }
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
    return "cam_from_lidar held constant (" +
           std::string(ChoiceName(kJointModeNames, options.mode)) + ")";
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

// The estimates besides cam_from_lidar that the run had as parameters: the LiDAR clock offset,
// the stereo depth's bias field, E_l's own angle about the driving direction.
void AddNuisanceParameters(const JointAdjustmentSummary& summary,
                           const LoadedJointData& loaded,
                           nlohmann::json* json) {
  nlohmann::json& report = *json;
  if (summary.time_offset) {
    report["time_offset"] = {{"lidar_minus_camera", *summary.time_offset},
                             {"unit", loaded.data.image_times.empty() ? "frames" : "s"}};
  }
  if (summary.oblique_offset_rad) {
    report["landmark_oblique_offset"] = {{"angle_mrad", 1000 * *summary.oblique_offset_rad}};
  }
  if (summary.depth_prior_bias) {
    const Eigen::Vector3d& bias = *summary.depth_prior_bias;
    report["depth_prior_bias"] = {{"inverse_depth_per_m", {bias.x(), bias.y(), bias.z()}},
                                  {"terms", {"1", "x", "y"}}};
  }
  if (!summary.lidar_free_axis_in_cam.isZero()) {
    const Eigen::Vector3d& axis = summary.lidar_free_axis_in_cam;
    report["lidar_free_rotation"] = {{"axis_in_cam", {axis.x(), axis.y(), axis.z()}},
                                     {"lidar_term_angle_deg", summary.lidar_free_angle_deg}};
  }
}

}  // namespace

void WriteJointReport(const std::string& directory,
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
  report["mode"] = std::string(ChoiceName(kJointModeNames, options.mode));
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
  if (options.landmark_lidar_weight > 0) {
    report["landmark_lidar_facing"] = LandmarkFacingJson(summary.landmark_lidar_facing);
  }
  report["variance_components"] = VarianceComponentsJson(options, summary);
  AddNuisanceParameters(summary, loaded, &report);
  report["extrinsic_measurements"] = MeasurementsJson(loaded.data.extrinsic_measurements, refined);
  report["start_departure"] =
      StartDepartureJson(CheckStartDeparture(initial, refined, loaded.data, summary));
  report["association"] = AssociationSettlingJson(CheckAssociationSettling(summary));
  const ExtrinsicUncertainty& u = summary.uncertainty;
  report["uncertainty"] = UncertaintyJson(u, options.observability, caveat);
  report["uncertainty"]["prior_determined_axes"] =
      PriorDeterminedAxes(u, loaded.data.extrinsic_measurements);
  report["unobservable"] = u.unobservable;
  report["held_directions"] = summary.held_directions;
  report["held_value"] = summary.held_at_guess ? "rig.json guess" : "start";
  report["hold_thresholds"] = {{"enabled", options.hold_unobservable},
                               {"rotation_deg", options.hold_rotation_deg},
                               {"translation_mm", options.hold_translation_mm}};
  report["motion"] = MotionJson(summary.motion);
  report["observability_verdict"] = ObservabilityVerdict(options, summary);
  nlohmann::json curves = nlohmann::json::array();
  for (const PerturbationCurve& curve : summary.perturbation) {
    curves.push_back({{"parameter", curve.parameter},
                      {"offsets", curve.offsets},
                      {"costs", curve.costs},
                      {"lidar_costs", curve.lidar_costs},
                      {"landmark_lidar_costs", curve.landmark_lidar_costs},
                      {"extrinsic_costs", curve.extrinsic_costs}});
  }
  report["perturbation"] = curves;
  WriteFileAtomically(directory + "/report.json", report.dump(2) + "\n");
}

void WriteJointPlots(const std::string& directory,
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
         "optimum (x y z in mm, roll pitch yaw in deg about the camera axes), and the terms that "
         "depend on it: LiDAR-to-LiDAR (E_l), landmark-to-LiDAR (E_m), extrinsic prior (E_x)\n"
      << "parameter,offset,cost,lidar,landmark_lidar,extrinsic\n";
  std::vector<PlotSeries> translation, rotation;
  for (const PerturbationCurve& curve : summary.perturbation) {
    PlotSeries series{curve.parameter, curve.offsets, curve.costs};
    (curve.parameter.size() == 1 ? translation : rotation).push_back(series);
    for (size_t k = 0; k < curve.offsets.size(); ++k) {
      csv << curve.parameter << "," << curve.offsets[k] << "," << std::setprecision(10)
          << curve.costs[k] << "," << curve.lidar_costs[k] << "," << curve.landmark_lidar_costs[k]
          << "," << curve.extrinsic_costs[k] << "\n";
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

namespace {

// One line per data term: its pull on cam_from_lidar in sigmas; a WARNING per disagreement.
void PrintTermPulls(const ExtrinsicUncertainty& u) {
  if (u.term_pulls.empty()) return;
  std::cout << "Each term's pull on cam_from_lidar (rx ry rz tx ty tz: in sigmas of "
               "cam_from_lidar, then as t, in its own clusters' scatter):"
            << std::endl;
  for (const TermPull& pull : u.term_pulls) {
    std::ostringstream line;
    line << std::fixed << std::setprecision(1) << "  " << std::left << std::setw(15) << pull.term
         << std::right;
    for (int k = 0; k < 6; ++k) line << " " << std::setw(6) << pull.pull_sigmas[k];
    line << "   t";
    for (int k = 0; k < 6; ++k) line << " " << std::setw(6) << pull.significance[k];
    std::cout << line.str() << std::endl;
  }
  for (const std::string& sentence : u.term_disagreements) {
    std::cout << "WARNING: " << sentence << std::endl;
  }
}

}  // namespace

void PrintJointUncertainty(const JointAdjustmentSummary& summary, const std::string& caveat) {
  std::cout << "Motion alone (the rotations between stations, without the structure's terms): "
            << summary.motion.verdict << std::endl;
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
    PrintTermPulls(summary.uncertainty);
  }
  for (const std::string& sentence : summary.uncertainty.unobservable) {
    std::cout << "UNOBSERVABLE: " << sentence << std::endl;
  }
  for (const std::string& direction : summary.held_directions) {
    std::cout << "HELD at " << (summary.held_at_guess ? "rig.json's guess" : "the initial value")
              << ": " << direction << std::endl;
  }
}

}  // namespace colmap_lidar
