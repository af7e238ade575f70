#include "bridge/joint/joint_adjuster.h"

#include "bridge/joint/camera_centre_observations.h"
#include "bridge/joint/extrinsic_deviation_cost.h"
#include "bridge/joint/extrinsic_prior_cost.h"
#include "bridge/joint/free_axis_extrinsic_cost.h"
#include "bridge/joint/landmark_lidar_plane_cost.h"
#include "bridge/joint/landmark_lidar_term.h"
#include "bridge/joint/lidar_pair_cost.h"
#include "bridge/joint/lidar_point_to_plane_cost.h"
#include "bridge/joint/start_departure.h"
#include "bridge/joint/subspace_manifold.h"
#include "bridge/joint/undetermined_parameters.h"
#include "colmap_ext/depth_prior_cost.h"
#include "colmap_ext/elapsed.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/rigid3_isometry.h"
#include "lidar/util/statistics.h"

#include "colmap/estimators/bundle_adjustment.h"
#include "colmap/estimators/cost_functions.h"
#include "colmap/scene/projection.h"

#include <ceres/ceres.h>

#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <memory>
#include <set>
#include <sstream>

namespace colmap_lidar {
namespace {

using ImagePoint = std::pair<colmap::image_t, colmap::point2D_t>;
using ImagePair = std::pair<colmap::image_t, colmap::image_t>;

// A LiDAR observation of the directed pair (target i, source j).
struct LidarObservation {
  colmap::image_t target = 0, source = 0;
  PointToPlaneObservation data;
  bool outlier = false;
};

// The observations of the association-dependent terms E_l and E_m, with their outlier flags.
struct Associations {
  std::vector<LidarObservation> lidar;
  std::vector<LandmarkPlaneObservation> landmarks;
};

double TermCost(ceres::Problem* problem, const std::vector<ceres::ResidualBlockId>& ids) {
  if (ids.empty()) return 0;
  ceres::Problem::EvaluateOptions options;
  options.residual_blocks = ids;
  double cost = 0;
  problem->Evaluate(options, &cost, nullptr, nullptr, nullptr);
  return cost;
}

}  // namespace

double MeanIterationSeconds(const ceres::Solver::Summary& summary) {
  double seconds = 0;
  for (size_t k = 1; k < summary.iterations.size(); ++k) {
    seconds += summary.iterations[k].iteration_time_in_seconds;
  }
  return summary.iterations.size() > 1 ? seconds / (summary.iterations.size() - 1) : 0.0;
}

namespace {

// lidar_i_from_lidar_j = inverse(T_e) cam_i_from_world inverse(cam_j_from_world) T_e.
colmap::Rigid3d LidarIFromLidarJ(const colmap::Rigid3d& cam_i_from_world,
                                 const colmap::Rigid3d& cam_j_from_world,
                                 const colmap::Rigid3d& cam_from_lidar) {
  return colmap::Inverse(cam_from_lidar) * cam_i_from_world * colmap::Inverse(cam_j_from_world) *
         cam_from_lidar;
}

std::unique_ptr<ceres::LossFunction> MakeLoss(RobustLoss loss, double scale) {
  switch (loss) {
    case RobustLoss::kNone:
      return nullptr;
    case RobustLoss::kHuber:
      return std::make_unique<ceres::HuberLoss>(scale);
    case RobustLoss::kCauchy:
      return std::make_unique<ceres::CauchyLoss>(scale);
  }
  return nullptr;
}

// The depth prior of a landmark observation, or null.
const DepthPrior* FindDepthPrior(const JointProblemData& data,
                                 const colmap::TrackElement& element) {
  const auto image_priors = data.depth_priors.find(element.image_id);
  if (image_priors == data.depth_priors.end()) return nullptr;
  const auto prior = image_priors->second.find(element.point2D_idx);
  return prior == image_priors->second.end() ? nullptr : &prior->second;
}

// The joint problem of one solve: COLMAP's bundle adjuster with our blocks injected.
struct JointProblem {
  // The reprojection residuals' loss (the robust loss scaled by the group's weight); declared before
  // the problem that uses it.
  std::unique_ptr<ceres::LossFunction> reprojection_loss;
  std::unique_ptr<colmap::BundleAdjuster> adjuster;
  std::shared_ptr<ceres::Problem> problem;
  colmap::BundleAdjustmentOptions ba_options;
  std::vector<ceres::ResidualBlockId> reprojection_ids;
  std::vector<ceres::ResidualBlockId> depth_ids;
  // Parallel to depth_ids: the image, and d(residual)/d(the stereo depth's consider parameters)
  // (ConsiderDerivative).
  std::vector<colmap::image_t> depth_images;
  std::vector<Eigen::Vector4d> depth_consider_derivatives;
  std::vector<ceres::ResidualBlockId> lidar_ids;
  std::vector<ImagePair> lidar_pairs;  // parallel to lidar_ids
  size_t num_lidar_residuals = 0;
  // Residuals that compressed LiDAR blocks stand for beyond the rows they have.
  size_t num_hidden_residuals = 0;
  std::vector<ceres::ResidualBlockId> landmark_ids;
  // E_x of the extrinsic measurement (data, known covariance), if any.
  std::vector<ceres::ResidualBlockId> measurement_ids;
  // The prior on E_m's oblique-view offset (outside knowledge with its covariance), if E_m is in.
  std::vector<ceres::ResidualBlockId> offset_prior_ids;
  std::vector<ceres::ResidualBlockId> prior_ids;
};

// Everything one Run() works on.
struct RunState {
  RunState(const JointAdjusterOptions& options,
           const JointProblemData& data,
           colmap::Reconstruction* reconstruction,
           colmap::Rigid3d* cam_from_lidar)
      : options(options),
        data(data),
        reconstruction(reconstruction),
        cam_from_lidar(cam_from_lidar),
        initial_rotation(cam_from_lidar->rotation),
        initial_translation(cam_from_lidar->translation),
        loss(MakeLoss(options.loss, options.loss_scale)),
        use_lidar(options.mode != JointMode::kStereoOnly && options.lidar_weight > 0),
        use_landmark_lidar(options.mode != JointMode::kStereoOnly &&
                           options.landmark_lidar_weight > 0),
        refine_extrinsic(options.mode == JointMode::kJoint) {}

  const JointAdjusterOptions& options;
  const JointProblemData& data;
  colmap::Reconstruction* reconstruction;
  colmap::Rigid3d* cam_from_lidar;
  colmap::BundleAdjustmentConfig config;
  const Eigen::Quaterniond initial_rotation;
  const Eigen::Vector3d initial_translation;
  // Projections onto the directions of T_e held at their initial value (zero: none held).
  Eigen::Matrix3d held_rotation = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d held_translation = Eigen::Matrix3d::Zero();
  // Owned here: COLMAP's problem does not take ownership of loss functions.
  std::unique_ptr<ceres::LossFunction> loss;
  const bool use_lidar;
  const bool use_landmark_lidar;
  const bool refine_extrinsic;
  VarianceFactors factors;
  std::set<ImagePoint> depth_outliers;
  size_t num_reprojection_outliers = 0;
  size_t num_lidar_outliers = 0;
  size_t num_landmark_outliers = 0;
  // This round's association gate (0 in the last round): E_m's outlier cap is never below it, so
  // that a coarse initial cam_from_lidar (a height off by 25 cm) is pulled in before the cap applies.
  double round_gate_m = 0;
  // Whether this round's problem has E_d (see JointAdjusterOptions::first_depth_prior_round).
  bool depth_priors_in_force = true;
  // JointAdjusterOptions::free_lidar_drive_roll: the axis (zero: off) and E_l's own angle about it,
  // a parameter block that lives across rounds.
  Eigen::Vector3d lidar_free_axis = Eigen::Vector3d::Zero();
  std::unique_ptr<double> lidar_free_angle = std::make_unique<double>(0.0);
  // JointAdjusterOptions::estimate_time_offset: dt, a parameter block that lives across rounds.
  std::unique_ptr<double> time_offset = std::make_unique<double>(0.0);
  // E_m's oblique-view offset delta [rad] (bridge/joint/landmark_lidar_plane_cost.h), a parameter
  // block that lives across rounds.
  std::unique_ptr<double> oblique_offset = std::make_unique<double>(0.0);
  // The stereo depth's bias field (colmap_ext/depth_prior_cost.h), a parameter block that lives
  // across rounds; estimated with estimate_depth_bias where E_m measures depth, else held at zero.
  std::unique_ptr<std::array<double, 3>> depth_prior_bias =
      std::make_unique<std::array<double, 3>>();

  bool UsesExtrinsic() const { return use_lidar || use_landmark_lidar; }
  bool EstimatesDepthBias() const {
    return options.estimate_depth_bias && use_landmark_lidar && options.depth_weight > 0;
  }

  double* ExtrinsicRotation() const { return cam_from_lidar->rotation.coeffs().data(); }
  double* ExtrinsicTranslation() const { return cam_from_lidar->translation.data(); }
  bool LidarHasFreeAxis() const { return use_lidar && !lidar_free_axis.isZero(); }
  // T_e as E_l sees it: exp(angle u) T_e with a free axis, else T_e.
  colmap::Rigid3d LidarTermExtrinsic() const {
    if (!LidarHasFreeAxis()) return *cam_from_lidar;
    return colmap::Rigid3d(
               Eigen::Quaterniond(Eigen::AngleAxisd(*lidar_free_angle, lidar_free_axis)),
               Eigen::Vector3d::Zero()) *
           *cam_from_lidar;
  }
};

colmap::BundleAdjustmentOptions JointBundleAdjustmentOptions(const JointAdjusterOptions& options) {
  colmap::BundleAdjustmentOptions ba;
  ba.refine_focal_length = false;  // the rig is calibrated
  ba.refine_principal_point = false;
  ba.refine_extra_params = false;
  ba.print_summary = false;
  ba.solver_options.max_num_iterations = options.max_num_iterations;
  ba.solver_options.function_tolerance = 1e-12;
  ba.solver_options.gradient_tolerance = 1e-14;
  ba.solver_options.parameter_tolerance = 1e-12;
  // One thread: Ceres' threaded evaluation and Schur elimination sum in the order threads finish,
  // which would make the result depend on the thread count.
  ba.solver_options.num_threads = 1;
  return ba;
}

// The pose blocks of an image; added (constant where COLMAP holds the pose constant) if COLMAP's
// problem does not have them (an image with no landmark).
std::pair<double*, double*> PoseBlocks(const RunState& state,
                                       ceres::Problem* problem,
                                       colmap::image_t image_id) {
  colmap::Rigid3d& pose = state.reconstruction->Image(image_id).CamFromWorld();
  double* rotation = pose.rotation.coeffs().data();
  double* translation = pose.translation.data();
  if (!problem->HasParameterBlock(rotation)) {
    problem->AddParameterBlock(rotation, 4);
    colmap::SetQuaternionManifold(problem, rotation);
    problem->AddParameterBlock(translation, 3);
    if (state.config.HasConstantCamPose(image_id)) {
      problem->SetParameterBlockConstant(rotation);
      problem->SetParameterBlockConstant(translation);
    }
  }
  return {rotation, translation};
}

// The depth prior of a landmark observation as the cost takes it, its sigma scaled by `weight_scale`.
DepthPriorMeasurement MeasurementOf(const RunState& state,
                                    const colmap::TrackElement& element,
                                    const DepthPrior& prior,
                                    double weight_scale) {
  const colmap::Image& image = state.reconstruction->Image(element.image_id);
  const Eigen::Vector2d& xy = image.Point2D(element.point2D_idx).xy;
  return {prior.depth,
          prior.sigma * weight_scale,
          state.reconstruction->Camera(image.CameraId()).CamFromImg(xy)};
}

// d(E_d)/d(the stereo depth's consider parameters) at zero: a relative scale error s (d -> d (1 + s))
// gives -d / sigma; a disparity error (1, x, y) . delta [px] moves 1/d by that over b f, so d by
// -d^2 (1, x, y) . delta / (b f). b f = 0: no field (no stereo rig, or the field is estimated).
Eigen::Vector4d ConsiderDerivative(const DepthPriorMeasurement& measurement,
                                   double baseline_focal) {
  const double d = measurement.depth;
  Eigen::Vector4d derivative = Eigen::Vector4d::Zero();
  derivative[0] = -d / measurement.sigma;
  if (baseline_focal > 0) {
    derivative.tail<3>() =
        d * d / (baseline_focal * measurement.sigma) *
        Eigen::Vector3d(1, measurement.normalized_xy.x(), measurement.normalized_xy.y());
  }
  return derivative;
}

// E_d, the paper's depth-prior residual, for every landmark observation with a prior in force.
void AddDepthPriorBlocks(const RunState& state, JointProblem* joint) {
  if (state.options.depth_weight <= 0 || !state.depth_priors_in_force) return;
  ceres::Problem* problem = joint->problem.get();
  double* bias = state.depth_prior_bias->data();
  const double weight_scale = std::sqrt(state.factors.depth / state.options.depth_weight);
  for (const auto& [point3D_id, point3D] : state.reconstruction->Points3D()) {
    double* xyz = state.reconstruction->Point3D(point3D_id).xyz.data();
    for (const colmap::TrackElement& element : point3D.track.Elements()) {
      const DepthPrior* prior = FindDepthPrior(state.data, element);
      if (prior == nullptr || state.depth_outliers.count({element.image_id, element.point2D_idx})) {
        continue;
      }
      const DepthPriorMeasurement measurement = MeasurementOf(state, element, *prior, weight_scale);
      joint->depth_images.push_back(element.image_id);
      // An estimated field is a parameter (marginalised), not a consider parameter.
      joint->depth_consider_derivatives.push_back(ConsiderDerivative(
          measurement, state.EstimatesDepthBias() ? 0.0 : state.data.stereo_baseline_focal));
      if (state.config.HasConstantCamPose(element.image_id)) {
        joint->depth_ids.push_back(problem->AddResidualBlock(
            DepthPriorConstantPoseCostFunctor::Create(
                state.reconstruction->Image(element.image_id).CamFromWorld(), measurement),
            state.loss.get(),
            xyz,
            bias));
      } else {
        const auto [rotation, translation] = PoseBlocks(state, problem, element.image_id);
        joint->depth_ids.push_back(
            problem->AddResidualBlock(DepthPriorCostFunctor::Create(measurement),
                                      state.loss.get(),
                                      {rotation, translation, xyz, bias}));
      }
    }
  }
  if (problem->HasParameterBlock(bias) && !state.EstimatesDepthBias()) {
    problem->SetParameterBlockConstant(bias);
  }
}

// Projection onto the translation directions held at the start: the user's axes and the
// directions the data do not determine.
Eigen::Matrix3d HeldTranslation(const RunState& state) {
  Eigen::Matrix3d held = state.held_translation;
  for (int i = 0; i < 3; ++i) {
    if (state.options.hold_translation[i]) held(i, i) = 1;
  }
  const Eigen::MatrixXd directions = HeldDirectionsOf(held);
  return directions * directions.transpose();
}

// Projection onto the rotation directions held at the start (all of them with hold_rotation).
Eigen::Matrix3d HeldRotation(const RunState& state) {
  return state.options.hold_rotation ? Eigen::Matrix3d::Identity() : state.held_rotation;
}

// A T_e block: constant when nothing of it is free, else its manifold without the held directions.
void SetExtrinsicManifold(const Eigen::Matrix3d& held,
                          std::unique_ptr<ceres::Manifold> manifold,
                          double* block,
                          ceres::Problem* problem) {
  const Eigen::MatrixXd free = FreeDirectionsBasis(held);
  if (free.cols() == 0) {
    problem->SetParameterBlockConstant(block);
  } else if (free.cols() == 3) {
    problem->SetManifold(block, manifold.release());
  } else {
    problem->SetManifold(block, new SubspaceManifold(std::move(manifold), free));
  }
}

// The shared T_e blocks, the degrees of freedom held (exactly: they are not in the blocks'
// tangent spaces), and the weak translation prior.
void AddExtrinsicBlocks(const RunState& state, JointProblem* joint) {
  ceres::Problem* problem = joint->problem.get();
  double* rotation = state.ExtrinsicRotation();
  double* translation = state.ExtrinsicTranslation();
  problem->AddParameterBlock(rotation, 4);
  problem->AddParameterBlock(translation, 3);
  const Eigen::Matrix3d all = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d held_translation = state.refine_extrinsic ? HeldTranslation(state) : all;
  SetExtrinsicManifold(state.refine_extrinsic ? HeldRotation(state) : all,
                       std::make_unique<ceres::EigenQuaternionManifold>(),
                       rotation,
                       problem);
  SetExtrinsicManifold(
      held_translation, std::make_unique<ceres::EuclideanManifold<3>>(), translation, problem);
  for (const ExtrinsicMeasurement& measurement : state.data.extrinsic_measurements) {
    if (!state.refine_extrinsic) break;
    joint->measurement_ids.push_back(problem->AddResidualBlock(
        ExtrinsicDeviationCostFunctor::Create(measurement.cam_from_lidar.rotation,
                                              measurement.cam_from_lidar.translation,
                                              WhiteningOfCovariance(measurement.covariance)),
        nullptr,
        rotation,
        translation));
  }
  if (!problem->IsParameterBlockConstant(translation) &&
      state.options.extrinsic_prior_sigma_m > 0) {
    joint->prior_ids.push_back(problem->AddResidualBlock(
        ExtrinsicTranslationPriorCostFunctor::Create(state.initial_translation,
                                                     state.options.extrinsic_prior_sigma_m),
        nullptr,
        translation));
  }
}

// E_l with the shared extrinsic: one analytic block per directed pair (observations of a pair are
// contiguous, see Associate), or one per observation when a robust loss must act per observation.
void AddLidarBlocks(const RunState& state,
                    const std::vector<LidarObservation>& observations,
                    JointProblem* joint) {
  ceres::Problem* problem = joint->problem.get();
  const double sigma =
      state.options.sigma_lidar_m * std::sqrt(state.factors.lidar / state.options.lidar_weight);
  const bool block_per_observation = state.loss != nullptr;
  std::vector<PointToPlaneObservation> group;
  for (size_t k = 0; k < observations.size(); ++k) {
    const LidarObservation& observation = observations[k];
    if (!observation.outlier) group.push_back(observation.data);
    const bool pair_ends = k + 1 == observations.size() ||
                           observations[k + 1].target != observation.target ||
                           observations[k + 1].source != observation.source;
    if (group.empty() || (!pair_ends && !block_per_observation)) continue;
    const auto [target_rotation, target_translation] =
        PoseBlocks(state, problem, observation.target);
    const auto [source_rotation, source_translation] =
        PoseBlocks(state, problem, observation.source);
    joint->num_lidar_residuals += group.size();
    if (state.options.compress_lidar_blocks &&
        group.size() > static_cast<size_t>(LidarPairPointToPlaneCost::kCompressedResiduals)) {
      joint->num_hidden_residuals += group.size() - LidarPairPointToPlaneCost::kCompressedResiduals;
    }
    joint->lidar_pairs.emplace_back(observation.target, observation.source);
    const colmap::Rigid3d reference =
        LidarIFromLidarJ(state.reconstruction->Image(observation.target).CamFromWorld(),
                         state.reconstruction->Image(observation.source).CamFromWorld(),
                         state.LidarTermExtrinsic());
    ceres::CostFunction* cost = LidarPairPointToPlaneCost::Create(
        std::move(group), sigma, state.options.compress_lidar_blocks, reference);
    std::vector<double*> blocks = {target_rotation,
                                   target_translation,
                                   source_rotation,
                                   source_translation,
                                   state.ExtrinsicRotation(),
                                   state.ExtrinsicTranslation()};
    if (state.LidarHasFreeAxis()) {
      cost = FreeAxisExtrinsicCost::Create(cost, state.lidar_free_axis);
      blocks.push_back(state.lidar_free_angle.get());
    }
    joint->lidar_ids.push_back(problem->AddResidualBlock(cost, state.loss.get(), blocks));
    group.clear();
  }
}

// Each registered image's camera velocity in its own frame, by central differences of the camera
// centres over the neighbouring images in time (image_id order, one unit apart, without times).
std::map<colmap::image_t, Eigen::Vector3d> CameraVelocities(
    const colmap::Reconstruction& reconstruction, const std::map<colmap::image_t, double>& times) {
  std::vector<std::pair<double, colmap::image_t>> order;
  for (const colmap::image_t image_id : reconstruction.RegImageIds()) {
    const auto time = times.find(image_id);
    if (!times.empty() && time == times.end()) continue;
    order.emplace_back(times.empty() ? static_cast<double>(image_id) : time->second, image_id);
  }
  std::sort(order.begin(), order.end());
  std::map<colmap::image_t, Eigen::Vector3d> velocities;
  if (order.size() < 2) return velocities;
  for (size_t k = 0; k < order.size(); ++k) {
    const size_t previous = k == 0 ? 0 : k - 1, next = std::min(k + 1, order.size() - 1);
    const colmap::Image& image = reconstruction.Image(order[k].second);
    const Eigen::Vector3d displacement =
        reconstruction.Image(order[next].second).ProjectionCenter() -
        reconstruction.Image(order[previous].second).ProjectionCenter();
    const double duration = order[next].first - order[previous].first;
    if (duration <= 0) continue;
    velocities[order[k].second] = image.CamFromWorld().rotation * displacement / duration;
  }
  return velocities;
}

// The prior sigma of E_m's oblique-view offset [rad]: a keypoint's systematic offset of at most
// about kObliqueOffsetPriorPx over the registered cameras' mean focal length.
double ObliqueOffsetPriorSigma(const colmap::Reconstruction& reconstruction) {
  constexpr double kObliqueOffsetPriorPx = 1.0;
  double focal_sum = 0;
  const std::vector<colmap::image_t> image_ids = reconstruction.RegImageIds();
  for (const colmap::image_t image_id : image_ids) {
    focal_sum += reconstruction.Camera(reconstruction.Image(image_id).CameraId()).MeanFocalLength();
  }
  return kObliqueOffsetPriorPx * static_cast<double>(image_ids.size()) / focal_sum;
}

// E_m for every associated landmark observation in force (the landmark and image still there).
void AddLandmarkLidarBlocks(const RunState& state,
                            const std::vector<LandmarkPlaneObservation>& observations,
                            JointProblem* joint) {
  ceres::Problem* problem = joint->problem.get();
  const std::map<colmap::image_t, Eigen::Vector3d> velocities =
      state.options.estimate_time_offset
          ? CameraVelocities(*state.reconstruction, state.data.image_times)
          : std::map<colmap::image_t, Eigen::Vector3d>();
  const double sigma =
      state.options.sigma_landmark_lidar_m *
      std::sqrt(state.factors.landmark_lidar / state.options.landmark_lidar_weight);
  for (const LandmarkPlaneObservation& observation : observations) {
    if (observation.outlier || !state.reconstruction->ExistsPoint3D(observation.point3D_id)) {
      continue;
    }
    const auto [rotation, translation] = PoseBlocks(state, problem, observation.image_id);
    const auto velocity = velocities.find(observation.image_id);
    if (velocity != velocities.end()) {
      joint->landmark_ids.push_back(problem->AddResidualBlock(
          TimedLandmarkLidarPlaneCostFunctor::Create(
              observation.point_in_lidar, observation.normal_in_lidar, velocity->second, sigma),
          state.loss.get(),
          {rotation,
           translation,
           state.reconstruction->Point3D(observation.point3D_id).xyz.data(),
           state.ExtrinsicRotation(),
           state.ExtrinsicTranslation(),
           state.oblique_offset.get(),
           state.time_offset.get()}));
      continue;
    }
    joint->landmark_ids.push_back(problem->AddResidualBlock(
        LandmarkLidarPlaneCostFunctor::Create(
            observation.point_in_lidar, observation.normal_in_lidar, sigma),
        state.loss.get(),
        {rotation,
         translation,
         state.reconstruction->Point3D(observation.point3D_id).xyz.data(),
         state.ExtrinsicRotation(),
         state.ExtrinsicTranslation(),
         state.oblique_offset.get()}));
  }
  if (joint->landmark_ids.empty()) return;
  if (!state.options.estimate_oblique_offset) {
    problem->SetParameterBlockConstant(state.oblique_offset.get());  // delta = 0
  } else {
    joint->offset_prior_ids.push_back(problem->AddResidualBlock(
        ObliqueOffsetPriorCostFunctor::Create(ObliqueOffsetPriorSigma(*state.reconstruction)),
        nullptr,
        state.oblique_offset.get()));
  }
}

std::unique_ptr<JointProblem> BuildProblem(const RunState& state,
                                           const Associations& associations) {
  auto joint = std::make_unique<JointProblem>();
  joint->ba_options = JointBundleAdjustmentOptions(state.options);
  joint->adjuster = std::make_unique<colmap::BundleAdjuster>(joint->ba_options, state.config);
  ceres::LossFunction* reprojection_loss = state.loss.get();
  if (state.factors.reprojection != 1) {
    joint->reprojection_loss = std::make_unique<ceres::ScaledLoss>(
        state.loss.get(), 1.0 / state.factors.reprojection, ceres::DO_NOT_TAKE_OWNERSHIP);
    reprojection_loss = joint->reprojection_loss.get();
  }
  joint->adjuster->SetUpProblem(state.reconstruction, reprojection_loss);
  joint->problem = joint->adjuster->Problem();
  std::vector<ceres::ResidualBlockId> all_ids;
  joint->problem->GetResidualBlocks(&all_ids);
  joint->reprojection_ids = all_ids;  // everything COLMAP added
  AddDepthPriorBlocks(state, joint.get());
  if (state.UsesExtrinsic()) AddExtrinsicBlocks(state, joint.get());
  if (state.use_lidar) AddLidarBlocks(state, associations.lidar, joint.get());
  if (state.use_landmark_lidar) {
    AddLandmarkLidarBlocks(state, associations.landmarks, joint.get());
  }
  return joint;
}

// Names of the joint problem's parameter blocks, for messages about them.
std::map<const double*, std::string> ParameterNames(const RunState& state) {
  std::map<const double*, std::string> names;
  for (const auto& [image_id, image] : state.reconstruction->Images()) {
    const colmap::Rigid3d& pose = image.CamFromWorld();
    names[pose.rotation.coeffs().data()] = "image '" + image.Name() + "' rotation";
    names[pose.translation.data()] = "image '" + image.Name() + "' translation";
  }
  for (const auto& [point3D_id, point3D] : state.reconstruction->Points3D()) {
    names[point3D.xyz.data()] = "landmark " + std::to_string(point3D_id) + " (seen in " +
                                std::to_string(point3D.track.Length()) + " images)";
  }
  names[state.ExtrinsicRotation()] = "cam_from_lidar rotation";
  names[state.ExtrinsicTranslation()] = "cam_from_lidar translation";
  names[state.time_offset.get()] = "the LiDAR clock offset";
  names[state.oblique_offset.get()] = "E_m's oblique-view offset";
  names[state.depth_prior_bias->data()] = "the stereo depth's bias field";
  names[state.lidar_free_angle.get()] = "E_l's free angle about the driving direction";
  return names;
}

// Ceres marks a step invalid when its linear solver fails (a normal matrix that is not positive
// definite) or the step cannot be evaluated; LM then retries with more damping. After a solve with
// failed steps the problem's undetermined parameters are found: landmarks the data do not determine
// (a track whose rays are nearly parallel) are returned, to leave the reconstruction as COLMAP
// filters such points; any other undetermined parameter (a pose, cam_from_lidar, the clock offset)
// is an error naming them: the damping would only move them by an amount nothing in the data
// decides.
std::vector<colmap::point3D_t> UndeterminedLandmarks(const RunState& state,
                                                     ceres::Problem* problem,
                                                     int invalid_steps) {
  const std::vector<UndeterminedBlock> blocks = UndeterminedBlocks(problem);
  std::map<const double*, colmap::point3D_t> landmark_of_block;
  for (const auto& [point3D_id, point3D] : state.reconstruction->Points3D()) {
    landmark_of_block[point3D.xyz.data()] = point3D_id;
  }
  std::vector<colmap::point3D_t> landmarks;
  std::vector<UndeterminedBlock> others;
  for (const UndeterminedBlock& block : blocks) {
    const auto landmark = landmark_of_block.find(block.block);
    if (landmark != landmark_of_block.end()) {
      landmarks.push_back(landmark->second);
    } else {
      others.push_back(block);
    }
  }
  if (others.empty()) {
    std::cout << "WARNING: " << invalid_steps
              << " steps of the solve failed (linear solver or evaluation); "
              << (landmarks.empty() ? "the problem's normal matrix is positive definite at its end"
                                    : std::to_string(landmarks.size()) +
                                          " landmark(s) the data do not determine leave the "
                                          "reconstruction")
              << std::endl;
    return landmarks;
  }
  const std::vector<std::string> undetermined = DescribeUndetermined(others, ParameterNames(state));
  std::ostringstream message;
  message << "the joint problem's normal matrix is not positive definite (" << invalid_steps
          << " failed steps): the data do not determine";
  for (size_t k = 0; k < undetermined.size() && k < 10; ++k)
    message << (k ? "; " : " ") << undetermined[k];
  if (undetermined.size() > 10) message << "; and " << undetermined.size() - 10 << " more";
  message << ". Hold what the data cannot see (--hold_rotation, --hold_translation) or give "
             "rig.json's cam_from_lidar_guess a sigma";
  throw std::runtime_error(message.str());
}

int NumInvalidSteps(const ceres::Solver::Summary& summary) {
  int invalid = 0;
  for (const ceres::IterationSummary& iteration : summary.iterations) {
    if (!iteration.step_is_valid && iteration.iteration > 0) ++invalid;
  }
  return invalid;
}

// `undetermined_landmarks`: those to leave the reconstruction (UndeterminedLandmarks).
SolveStats Solve(const RunState& state,
                 JointProblem* joint,
                 std::vector<colmap::point3D_t>* undetermined_landmarks) {
  ceres::Problem* problem = joint->problem.get();
  SolveStats stats;
  stats.reprojection.num_observations = joint->reprojection_ids.size();
  stats.depth.num_observations = joint->depth_ids.size();
  stats.lidar.num_observations = joint->num_lidar_residuals;
  stats.landmark_lidar.num_observations = joint->landmark_ids.size();
  stats.reprojection.cost_before = TermCost(problem, joint->reprojection_ids);
  stats.depth.cost_before = TermCost(problem, joint->depth_ids);
  stats.lidar.cost_before = TermCost(problem, joint->lidar_ids);
  stats.landmark_lidar.cost_before = TermCost(problem, joint->landmark_ids);
  const ceres::Solver::Options solver_options =
      joint->adjuster->SetUpSolverOptions(*problem, joint->ba_options.solver_options);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, problem, &summary);
  stats.reprojection.cost_after = TermCost(problem, joint->reprojection_ids);
  stats.depth.cost_after = TermCost(problem, joint->depth_ids);
  stats.lidar.cost_after = TermCost(problem, joint->lidar_ids);
  stats.landmark_lidar.cost_after = TermCost(problem, joint->landmark_ids);
  stats.num_iterations = static_cast<int>(summary.iterations.size());
  stats.seconds_per_iteration = MeanIterationSeconds(summary);
  stats.residual_blocks = static_cast<size_t>(summary.num_residual_blocks);
  stats.residuals = static_cast<size_t>(summary.num_residuals);
  stats.termination = ceres::TerminationTypeToString(summary.termination_type);
  stats.invalid_steps = NumInvalidSteps(summary);
  // A landmark at a camera's centre makes that camera's pose look undetermined; its observation
  // leaves first (RemoveObservationsAtCameraCentres) and the solve runs again.
  if (stats.invalid_steps > 0 && ObservationsAtCameraCentres(*state.reconstruction).empty()) {
    *undetermined_landmarks = UndeterminedLandmarks(state, problem, stats.invalid_steps);
  }
  return stats;
}

// Deletes `observations` still in the reconstruction; returns how many. Deleting an observation
// deletes the whole landmark when its track drops below two.
size_t DeleteObservations(const std::vector<ImagePoint>& observations,
                          colmap::Reconstruction* reconstruction) {
  size_t deleted = 0;
  for (const ImagePoint& observation : observations) {
    if (reconstruction->Image(observation.first).Point2D(observation.second).HasPoint3D()) {
      reconstruction->DeleteObservation(observation.first, observation.second);
      ++deleted;
    }
  }
  return deleted;
}

// Reprojection outliers (> max px) leave the reconstruction, as in COLMAP's filtering; returns how many.
size_t RemoveReprojectionOutliers(RunState* state) {
  colmap::Reconstruction& reconstruction = *state->reconstruction;
  const double max_squared =
      state->options.max_reprojection_error_px * state->options.max_reprojection_error_px;
  std::vector<ImagePoint> bad;
  for (const auto& [point3D_id, point3D] : reconstruction.Points3D()) {
    for (const colmap::TrackElement& element : point3D.track.Elements()) {
      const colmap::Image& image = reconstruction.Image(element.image_id);
      if (colmap::CalculateSquaredReprojectionError(image.Point2D(element.point2D_idx).xy,
                                                    point3D.xyz,
                                                    image.CamFromWorld(),
                                                    reconstruction.Camera(image.CameraId())) >
          max_squared) {
        bad.emplace_back(element.image_id, element.point2D_idx);
      }
    }
  }
  const size_t removed = DeleteObservations(bad, &reconstruction);
  state->num_reprojection_outliers += removed;
  return removed;
}

// Observations of landmarks at their camera's centre (ObservationsAtCameraCentres) leave the
// reconstruction; returns how many.
size_t RemoveObservationsAtCameraCentres(RunState* state) {
  const size_t removed = DeleteObservations(ObservationsAtCameraCentres(*state->reconstruction),
                                            state->reconstruction);
  if (removed > 0) {
    std::cout << "  " << removed
              << " observation(s) of a landmark at the observing camera's centre leave the "
                 "reconstruction"
              << std::endl;
  }
  return removed;
}

// Robust scale of normalised errors: 1.4826 median |e|, clamped to [kMinScale, 1].
double RobustScale(std::vector<double> normalised) {
  constexpr double kMinScale = 0.1;
  if (normalised.empty()) return 1.0;
  return std::clamp(1.4826 * Median(std::move(normalised)), kMinScale, 1.0);
}

// Depth priors: the outlier set recomputed from the current state (a prior that fits again comes
// back). Returns the number of priors whose status changed.
size_t UpdateDepthOutliers(RunState* state, DepthOutlierStats* stats) {
  const JointAdjusterOptions& options = state->options;
  struct Check {
    ImagePoint key;
    double error, sigma;
  };
  std::vector<Check> checks;
  std::vector<double> normalised;
  for (const auto& [point3D_id, point3D] : state->reconstruction->Points3D()) {
    for (const colmap::TrackElement& element : point3D.track.Elements()) {
      const DepthPrior* prior = FindDepthPrior(state->data, element);
      if (prior == nullptr) continue;
      const colmap::Image& image = state->reconstruction->Image(element.image_id);
      const double error = std::abs((image.CamFromWorld() * point3D.xyz).z() -
                                    CorrectedDepth(MeasurementOf(*state, element, *prior, 1.0),
                                                   state->depth_prior_bias->data()));
      checks.push_back({{element.image_id, element.point2D_idx}, error, prior->sigma});
      normalised.push_back(error / prior->sigma);
    }
  }
  stats->residual_scale = RobustScale(std::move(normalised));
  // The gate in units of the priors' estimated sigma (their variance factor), or of their robust
  // residual scale without variance components.
  const double scale = options.estimate_variance_components     ? std::sqrt(state->factors.depth)
                       : options.depth_gate_from_residual_scale ? stats->residual_scale
                                                                : 1.0;
  const double gate_sigmas = options.max_depth_error_sigmas * scale;
  std::set<ImagePoint> outliers;
  size_t changed = 0;
  for (const Check& check : checks) {
    const bool beyond_sigma = check.error > gate_sigmas * check.sigma;
    const bool beyond_absolute =
        options.max_depth_error_m > 0 && check.error > options.max_depth_error_m;
    const bool was_outlier = state->depth_outliers.count(check.key) > 0;
    if (beyond_sigma || beyond_absolute) {
      outliers.insert(check.key);
      stats->beyond_sigma += beyond_sigma;
      stats->beyond_absolute += !beyond_sigma;
      changed += !was_outlier;
    } else if (was_outlier) {
      ++stats->restored;
      ++changed;
    }
  }
  state->depth_outliers = std::move(outliers);
  return changed;
}

// LiDAR observations beyond max_point_to_plane_m get zero weight; returns how many new.
size_t FlagLidarOutliers(RunState* state, std::vector<LidarObservation>* observations) {
  size_t flagged = 0;
  for (LidarObservation& observation : *observations) {
    if (observation.outlier) continue;
    const colmap::Rigid3d target_from_source =
        LidarIFromLidarJ(state->reconstruction->Image(observation.target).CamFromWorld(),
                         state->reconstruction->Image(observation.source).CamFromWorld(),
                         state->LidarTermExtrinsic());
    const double distance = observation.data.normal_in_target.dot(
        target_from_source * observation.data.point_in_source - observation.data.point_in_target);
    if (std::abs(distance) > state->options.max_point_to_plane_m) {
      observation.outlier = true;
      ++flagged;
    }
  }
  state->num_lidar_outliers += flagged;
  return flagged;
}

// E_m observations beyond the absolute or the sigma gate get zero weight; returns how many new. The
// gate is in units of the nominal sigma_m, not of its estimate: E_m's residuals are heavy-tailed (a
// landmark near a plane's edge), and a gate that follows the estimate would clip the tails round
// after round, each round's smaller estimate narrowing the next gate.
size_t FlagLandmarkOutliers(RunState* state, std::vector<LandmarkPlaneObservation>* observations) {
  const double gate = std::max(
      state->round_gate_m,
      std::min(state->options.max_landmark_plane_m,
               state->options.max_landmark_plane_sigmas * state->options.sigma_landmark_lidar_m));
  const std::map<colmap::image_t, Eigen::Vector3d> velocities =
      state->options.estimate_time_offset
          ? CameraVelocities(*state->reconstruction, state->data.image_times)
          : std::map<colmap::image_t, Eigen::Vector3d>();
  size_t flagged = 0;
  for (LandmarkPlaneObservation& observation : *observations) {
    if (observation.outlier) continue;
    colmap::Rigid3d cam_from_lidar = *state->cam_from_lidar;  // station i's, with dt
    const auto velocity = velocities.find(observation.image_id);
    if (velocity != velocities.end()) {
      cam_from_lidar.translation += *state->time_offset * velocity->second;
    }
    const double distance =
        LandmarkPlaneDistance(observation, *state->reconstruction, cam_from_lidar);
    if (std::isnan(distance) || std::abs(distance) > gate) {
      observation.outlier = true;
      ++flagged;
    }
  }
  state->num_landmark_outliers += flagged;
  return flagged;
}

// Point-to-plane observations of every directed pair of the pose graph, contiguous per pair.
std::vector<LidarObservation> Associate(const RunState& state, double max_distance) {
  const colmap::Reconstruction& reconstruction = *state.reconstruction;
  std::vector<ImagePair> directed;
  for (const auto& [a, b] : state.data.pairs) {
    if (!reconstruction.ExistsImage(a) || !reconstruction.ExistsImage(b) ||
        !reconstruction.Image(a).IsRegistered() || !reconstruction.Image(b).IsRegistered() ||
        !state.data.clouds.count(a) || !state.data.clouds.count(b)) {
      continue;
    }
    directed.emplace_back(a, b);
    directed.emplace_back(b, a);
  }
  std::vector<std::vector<LidarObservation>> per_pair(directed.size());
  const colmap::Rigid3d cam_from_lidar = state.LidarTermExtrinsic();
#pragma omp parallel for schedule(dynamic)
  for (int k = 0; k < static_cast<int>(directed.size()); ++k) {
    const auto [target, source] = directed[k];
    const StationCloud& target_cloud = *state.data.clouds.at(target);
    AssociationOptions association = state.options.association;
    association.max_distance = max_distance;
    association.seed = state.options.association.seed + 7919 * k;
    const colmap::Rigid3d target_from_source =
        LidarIFromLidarJ(reconstruction.Image(target).CamFromWorld(),
                         reconstruction.Image(source).CamFromWorld(),
                         cam_from_lidar);
    for (const PointToPlaneObservation& observation : AssociatePointToPlane(
             state.data.clouds.at(source)->cloud,
             target_cloud.cloud,
             *target_cloud.tree,
             ToIsometry(target_from_source),
             association,
             {&target_cloud.curvature, &state.data.clouds.at(source)->curvature})) {
      per_pair[k].push_back({target, source, observation, false});
    }
  }
  std::vector<LidarObservation> observations;
  for (auto& pair : per_pair) observations.insert(observations.end(), pair.begin(), pair.end());
  return observations;
}

// Round `round`'s associations of E_l and E_m, with the gate halved per round down to the final one.
void Reassociate(int round, int num_rounds, RunState* state, Associations* associations) {
  const JointAdjusterOptions& options = state->options;
  const double gate = std::max(options.association.max_distance,
                               options.initial_association_distance_m * std::pow(0.5, round));
  const auto start = std::chrono::steady_clock::now();
  state->round_gate_m = round + 1 < num_rounds ? gate : 0.0;  // the last round: the final cap
  if (state->use_lidar) associations->lidar = Associate(*state, gate);
  if (state->use_landmark_lidar) {
    associations->landmarks = AssociateLandmarksWithLidar(*state->reconstruction,
                                                          state->data.clouds,
                                                          *state->cam_from_lidar,
                                                          gate,
                                                          options.association.max_curvature);
  }
  state->num_lidar_outliers = 0;
  state->num_landmark_outliers = 0;
  std::cout << "Round " << round + 1 << "/"
            << (round < num_rounds ? std::to_string(num_rounds)
                                   : "+ (T_e or the weights still moving)")
            << ": " << associations->lidar.size() << " LiDAR point-to-plane observations, "
            << associations->landmarks.size() << " landmark-to-LiDAR-plane observations (gate "
            << gate << " m, " << SecondsSince(start) << " s)" << std::endl;
}

void PrintSolve(const SolveStats& stats, size_t changes) {
  std::cout << std::defaultfloat << std::setprecision(4) << "  solve " << stats.round << "."
            << stats.outlier_iteration << ": cost reprojection " << stats.reprojection.cost_before
            << " -> " << stats.reprojection.cost_after << ", depth " << stats.depth.cost_before
            << " -> " << stats.depth.cost_after << ", lidar " << stats.lidar.cost_before << " -> "
            << stats.lidar.cost_after;
  if (stats.landmark_lidar.num_observations > 0) {
    std::cout << ", landmark-lidar " << stats.landmark_lidar.cost_before << " -> "
              << stats.landmark_lidar.cost_after;
  }
  std::cout << "; " << stats.num_iterations << " iterations, " << changes
            << " outlier changes (depth priors: residual scale "
            << stats.depth_outliers.residual_scale << " sigma_d, out "
            << stats.depth_outliers.beyond_sigma << " beyond sigma, "
            << stats.depth_outliers.beyond_absolute << " beyond the cap, "
            << stats.depth_outliers.restored << " back) (" << std::setprecision(2) << stats.seconds
            << " s)" << std::endl;
}

// Solves until no outlier status changes (or the cap); `observations` keeps its outlier flags.
void SolveWithOutliers(int round,
                       RunState* state,
                       Associations* associations,
                       JointAdjustmentSummary* summary) {
  for (int iteration = 0; iteration < state->options.max_outlier_iterations; ++iteration) {
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<JointProblem> joint = BuildProblem(*state, *associations);
    std::vector<colmap::point3D_t> undetermined;
    SolveStats stats = Solve(*state, joint.get(), &undetermined);
    joint.reset();  // before the reconstruction changes under it
    for (const colmap::point3D_t point3D_id : undetermined) {
      state->reconstruction->DeletePoint3D(point3D_id);
    }
    stats.round = round + 1;
    stats.outlier_iteration = iteration + 1;
    stats.observations_at_camera_centres = RemoveObservationsAtCameraCentres(state);
    size_t changes = undetermined.size() + stats.observations_at_camera_centres;
    changes += RemoveReprojectionOutliers(state);
    changes += UpdateDepthOutliers(state, &stats.depth_outliers);
    changes += FlagLidarOutliers(state, &associations->lidar);
    changes += FlagLandmarkOutliers(state, &associations->landmarks);
    stats.reprojection.num_outliers = state->num_reprojection_outliers;
    stats.depth.num_outliers = state->depth_outliers.size();
    stats.lidar.num_outliers = state->num_lidar_outliers;
    stats.landmark_lidar.num_outliers = state->num_landmark_outliers;
    stats.seconds = SecondsSince(start);
    PrintSolve(stats, changes);
    summary->solves.push_back(stats);
    if (changes == 0) break;
  }
}

size_t NumResiduals(ceres::Problem* problem, const std::vector<ceres::ResidualBlockId>& ids) {
  size_t count = 0;
  for (const ceres::ResidualBlockId id : ids) {
    count += problem->GetCostFunctionForResidualBlock(id)->num_residuals();
  }
  return count;
}

// The variance components at the current state (on a problem built for them); each group's factor is
// multiplied by its estimate (a group without residuals or redundancy keeps its factor). Returns the
// components; `changed`: whether a factor moved by more than kFactorTolerance.
std::vector<VarianceComponent> UpdateVarianceFactors(RunState* state,
                                                     const Associations& associations,
                                                     bool* changed) {
  constexpr double kFactorTolerance = 0.1;
  const std::unique_ptr<JointProblem> joint = BuildProblem(*state, associations);
  ceres::Problem* problem = joint->problem.get();
  const std::vector<VarianceGroup> groups = {
      {"reprojection", joint->reprojection_ids, NumResiduals(problem, joint->reprojection_ids)},
      {"depth_prior", joint->depth_ids, joint->depth_ids.size()},
      {"lidar", joint->lidar_ids, joint->num_lidar_residuals},
      {"landmark_lidar", joint->landmark_ids, joint->landmark_ids.size()}};
  std::vector<ceres::ResidualBlockId> fixed = joint->prior_ids;
  fixed.insert(fixed.end(), joint->measurement_ids.begin(), joint->measurement_ids.end());
  fixed.insert(fixed.end(), joint->offset_prior_ids.begin(), joint->offset_prior_ids.end());
  const std::vector<VarianceComponent> components =
      EstimateVarianceComponents(problem, groups, fixed);
  double* factors[4] = {&state->factors.reprojection,
                        &state->factors.depth,
                        &state->factors.lidar,
                        &state->factors.landmark_lidar};
  *changed = false;
  std::cout << "  variance components (sigma / nominal sigma):";
  for (size_t g = 0; g < groups.size(); ++g) {
    if (components[g].num_observations == 0 || components[g].redundancy <= 0.5) continue;
    *factors[g] *= components[g].factor;
    *changed = *changed || std::abs(components[g].factor - 1) > kFactorTolerance;
    std::cout << " " << components[g].name << " " << std::sqrt(*factors[g]) << " (redundancy "
              << std::llround(components[g].redundancy) << ")";
  }
  std::cout << std::endl;
  return components;
}

// Clusters of residuals for the two-way cluster-robust covariance (Cameron, Gelbach & Miller 2011):
// residuals share errors by landmark (its keypoints' texture, its surface) and by one sensor's
// capture at one station (the image's errors shared by its reprojections, the depth map's by its
// priors, the sweep's by the LiDAR pairs it is the target of). A cluster is one landmark's
// residuals of one kind in one station, an image's depth priors, or a directed LiDAR pair; its
// group keys are its landmark (-1: none) and its station-and-kind. The weak extrinsic prior is not
// data and is left out.
enum class ResidualKind { kReprojection = 0, kLandmarkLidar = 1, kDepthPrior = 2, kLidarPair = 3 };
constexpr int kNumResidualKinds = 4;
// The kinds' names in report.json (those of the variance components).
constexpr const char* kResidualKindNames[kNumResidualKinds] = {
    "reprojection", "landmark_lidar", "depth_prior", "lidar"};

struct Clusters {
  std::vector<std::vector<ceres::ResidualBlockId>> blocks;
  std::vector<std::array<int, 2>> groups;
  std::vector<int> kinds;
  std::map<std::array<int, 3>, size_t> index;  // (kind, key, key) -> cluster

  void Add(ceres::ResidualBlockId id, ResidualKind kind, int key, int landmark, int station) {
    const int kind_index = static_cast<int>(kind);
    const auto [it, inserted] =
        index.emplace(std::array<int, 3>{kind_index, key, station}, blocks.size());
    if (inserted) {
      blocks.emplace_back();
      groups.push_back({landmark, station * kNumResidualKinds + kind_index});
      kinds.push_back(kind_index);
    }
    blocks[it->second].push_back(id);
  }
};

// The landmark and the station of a reprojection or landmark-to-plane residual, from its parameter
// blocks: the landmark's position and the first camera pose among them; a residual without a pose
// block (COLMAP's constant-pose reprojection) is the gauge image's.
std::array<int, 2> LandmarkAndStation(const JointProblem& joint,
                                      ceres::ResidualBlockId id,
                                      const std::unordered_map<const double*, int>& landmark_keys,
                                      const std::unordered_map<const double*, int>& station_keys,
                                      int gauge_station) {
  std::vector<double*> blocks;
  joint.problem->GetParameterBlocksForResidualBlock(id, &blocks);
  std::array<int, 2> keys = {-1, gauge_station};
  for (const double* block : blocks) {
    if (const auto it = landmark_keys.find(block); it != landmark_keys.end()) keys[0] = it->second;
  }
  for (const double* block : blocks) {
    if (const auto it = station_keys.find(block); it != station_keys.end()) {
      keys[1] = it->second;
      break;
    }
  }
  return keys;
}

Clusters ResidualClusters(const RunState& state, const JointProblem& joint) {
  std::unordered_map<const double*, int> landmark_keys, station_keys;
  for (const auto& [point3D_id, point3D] : state.reconstruction->Points3D()) {
    landmark_keys.emplace(point3D.xyz.data(), static_cast<int>(landmark_keys.size()));
  }
  int gauge_station = -1;
  for (const auto& [image_id, image] : state.reconstruction->Images()) {
    station_keys.emplace(image.CamFromWorld().rotation.coeffs().data(), static_cast<int>(image_id));
    if (state.config.HasConstantCamPose(image_id)) gauge_station = static_cast<int>(image_id);
  }
  Clusters clusters;
  for (const ResidualKind kind : {ResidualKind::kReprojection, ResidualKind::kLandmarkLidar}) {
    const auto& ids =
        kind == ResidualKind::kReprojection ? joint.reprojection_ids : joint.landmark_ids;
    for (const ceres::ResidualBlockId id : ids) {
      const auto [landmark, station] =
          LandmarkAndStation(joint, id, landmark_keys, station_keys, gauge_station);
      clusters.Add(id, kind, landmark, landmark, station);
    }
  }
  for (size_t k = 0; k < joint.depth_ids.size(); ++k) {
    const int station = static_cast<int>(joint.depth_images[k]);
    clusters.Add(joint.depth_ids[k], ResidualKind::kDepthPrior, -1, -1, station);
  }
  for (size_t k = 0; k < joint.lidar_ids.size(); ++k) {
    const auto [target, source] = joint.lidar_pairs[k];
    clusters.Add(joint.lidar_ids[k],
                 ResidualKind::kLidarPair,
                 static_cast<int>(source),
                 -1,
                 static_cast<int>(target));
  }
  return clusters;
}

ExtrinsicUncertainty Uncertainty(const RunState& state,
                                 const JointProblem& joint,
                                 const MotionAnalysis& motion) {
  ExtrinsicUncertaintyInputs inputs;
  inputs.problem = joint.problem.get();
  inputs.cam_from_lidar_rotation = state.ExtrinsicRotation();
  inputs.cam_from_lidar_translation = state.ExtrinsicTranslation();
  inputs.held_rotation = HeldRotation(state);
  inputs.held_translation = HeldTranslation(state);
  inputs.undetermined_rotation = state.held_rotation;
  inputs.undetermined_translation = state.held_translation;
  for (size_t k = 0; k < joint.depth_ids.size(); ++k) {
    inputs.depth_consider_derivative[joint.depth_ids[k]] = joint.depth_consider_derivatives[k];
  }
  Clusters clusters = ResidualClusters(state, joint);
  inputs.clusters = std::move(clusters.blocks);
  if (state.options.observability.cluster_grouping ==
      ObservabilityOptions::ClusterGrouping::kLandmark) {
    for (std::array<int, 2>& keys : clusters.groups) keys[1] = -1;  // each its own capture group
  }
  inputs.cluster_groups = std::move(clusters.groups);
  inputs.cluster_term = std::move(clusters.kinds);
  inputs.term_names.assign(std::begin(kResidualKindNames), std::end(kResidualKindNames));
  inputs.regularizers = joint.prior_ids;
  inputs.measurements = joint.measurement_ids;
  inputs.measurements.insert(
      inputs.measurements.end(), joint.offset_prior_ids.begin(), joint.offset_prior_ids.end());
  inputs.hidden_residuals = joint.num_hidden_residuals;
  ExtrinsicUncertainty uncertainty =
      ComputeExtrinsicUncertainty(inputs, motion, state.options.observability);
  if (joint.reprojection_ids.empty() && joint.depth_ids.empty()) {
    uncertainty.unobservable.insert(
        uncertainty.unobservable.begin(),
        "cam_from_lidar cannot be calibrated: no image landmark ties the cameras together, so the "
        "LiDAR fixes only the LiDAR poses and cam_from_lidar keeps its initial value; add "
        "overlapping images (more stations, or closer spacing)");
  }
  return uncertainty;
}

// The paper's perturbation curves: only E_l (and E_m, E_x) depend on T_e, so the total is the rest
// (constant) plus those terms at the perturbed T_e. Offsets are true rotation angles about the camera axes.
std::vector<PerturbationCurve> PerturbationCurves(const RunState& state, JointProblem* joint) {
  ceres::Problem* problem = joint->problem.get();
  const double rest =
      TermCost(problem, joint->reprojection_ids) + TermCost(problem, joint->depth_ids);
  colmap::Rigid3d& cam_from_lidar = *state.cam_from_lidar;
  const colmap::Rigid3d optimum = cam_from_lidar;
  static const char* kNames[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  std::vector<PerturbationCurve> curves;
  for (int dof = 0; dof < 6; ++dof) {
    PerturbationCurve curve;
    curve.parameter = kNames[dof];
    for (int step = -10; step <= 10; ++step) {
      const double offset = step * (dof < 3 ? 2.0 : 0.1);  // +-20 mm, +-1 deg
      cam_from_lidar = optimum;
      if (dof < 3) {
        cam_from_lidar.translation[dof] += offset / 1000.0;
      } else {
        cam_from_lidar.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(
                                      offset * M_PI / 180, Eigen::Vector3d::Unit(dof - 3))) *
                                  optimum.rotation;
      }
      curve.offsets.push_back(offset);
      curve.lidar_costs.push_back(TermCost(problem, joint->lidar_ids));
      curve.landmark_lidar_costs.push_back(TermCost(problem, joint->landmark_ids));
      curve.extrinsic_costs.push_back(TermCost(problem, joint->measurement_ids));
      curve.costs.push_back(rest + curve.lidar_costs.back() + curve.landmark_lidar_costs.back() +
                            curve.extrinsic_costs.back());
    }
    curves.push_back(curve);
  }
  cam_from_lidar = optimum;
  return curves;
}

// The directions of T_e whose standard deviation exceeds observability's thresholds, per block
// (rotation [deg], translation [mm]) of the covariance, as projections and in words.
struct HeldDirections {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d translation = Eigen::Matrix3d::Zero();
  std::vector<std::string> names;
};

// JointAdjusterOptions::free_lidar_drive_roll: the direction of travel in the camera frame without
// its component along the common turn axis; zero if off, without E_l, or the stations do not move.
Eigen::Vector3d LidarFreeAxis(const JointAdjusterOptions& options,
                              const colmap::Reconstruction& reconstruction) {
  if (!options.free_lidar_drive_roll || options.mode != JointMode::kJoint ||
      options.lidar_weight <= 0) {
    return Eigen::Vector3d::Zero();
  }
  const MotionAnalysis motion = AnalyseMotion(reconstruction, options.observability);
  const Eigen::Vector3d& turn = motion.common_axis_in_cam;
  const Eigen::Vector3d axis =
      motion.travel_direction_in_cam - turn.dot(motion.travel_direction_in_cam) * turn;
  if (axis.norm() < 0.5) return Eigen::Vector3d::Zero();
  std::cout << "E_l leaves the rotation about the driving direction (camera "
            << axis.normalized().transpose() << ") to the other terms" << std::endl;
  return axis.normalized();
}

// How far a round moved T_e: rotation (deg), translation (mm).
std::array<double, 2> ExtrinsicChange(const colmap::Rigid3d& before, const colmap::Rigid3d& after) {
  return {before.rotation.angularDistance(after.rotation) * 180 / M_PI,
          1000 * (before.translation - after.translation).norm()};
}

// E_m's final associations by the camera axis their surface faces into `summary`, printed.
void RecordLandmarkFacing(const RunState& state,
                          const Associations& associations,
                          JointAdjustmentSummary* summary) {
  if (!state.use_landmark_lidar) return;
  summary->landmark_lidar_facing =
      SummariseByFacingAxis(associations.landmarks, *state.reconstruction, *state.cam_from_lidar);
  const auto& facing = summary->landmark_lidar_facing;
  std::cout << "E_m observations by the camera axis their surface faces: x "
            << facing[0].num_observations << ", y " << facing[1].num_observations << ", z "
            << facing[2].num_observations << std::endl;
}

// The stereo depth's estimated bias field into `summary`, printed; or why it stayed at zero.
void RecordDepthBias(const RunState& state, JointAdjustmentSummary* summary) {
  if (state.options.estimate_depth_bias && !state.EstimatesDepthBias()) {
    std::cout << "The stereo depth's bias field is held at zero: no landmark-to-LiDAR-plane term "
                 "(E_m) measures depth against the LiDAR in this run"
              << std::endl;
  }
  if (state.EstimatesDepthBias() && !state.data.depth_priors.empty()) {
    const std::array<double, 3>& bias = *state.depth_prior_bias;
    summary->depth_prior_bias = Eigen::Vector3d(bias[0], bias[1], bias[2]);
    std::cout << "Stereo depth bias field (1/depth, 1/m): " << bias[0] << " + " << bias[1]
              << " x + " << bias[2] << " y; a prior of 10 m on the optical axis is corrected by "
              << 1000 * (1 / (0.1 + bias[0]) - 10) << " mm" << std::endl;
  }
}

// The state's free LiDAR rotation, variance factors, clock offset and E_m's surfaces into `summary`,
// printed.
void RecordFinalState(const RunState& state,
                      const JointProblemData& data,
                      const Associations& associations,
                      JointAdjustmentSummary* summary) {
  RecordLandmarkFacing(state, associations, summary);
  if (state.LidarHasFreeAxis()) {
    summary->lidar_free_axis_in_cam = state.lidar_free_axis;
    summary->lidar_free_angle_deg = *state.lidar_free_angle * 180 / M_PI;
    std::cout << "E_l's own rotation about the driving direction: " << summary->lidar_free_angle_deg
              << " deg from cam_from_lidar" << std::endl;
  }
  summary->variance_factors = state.factors;
  RecordDepthBias(state, summary);
  if (state.use_landmark_lidar && state.options.estimate_oblique_offset) {
    summary->oblique_offset_rad = *state.oblique_offset;
    std::cout << "E_m's oblique-view offset: delta " << 1000 * *state.oblique_offset
              << " mrad (landmarks towards the sensors by delta d sin tan of the ray's angle to "
                 "the surface normal)"
              << std::endl;
  }
  if (state.options.estimate_time_offset) {
    summary->time_offset = *state.time_offset;
    std::cout << "LiDAR clock offset from the cameras (E_m): " << *state.time_offset
              << (data.image_times.empty() ? " frames" : " s") << std::endl;
  }
}

// Whether the last round still moved T_e (so that another round at the final gate is due).
bool RoundMovedExtrinsic(const JointAdjusterOptions& options,
                         const JointAdjustmentSummary& summary) {
  if (summary.extrinsic_change_per_round.empty()) return false;
  const std::array<double, 2>& last = summary.extrinsic_change_per_round.back();
  return last[0] > options.round_convergence_deg || last[1] > options.round_convergence_mm;
}

HeldDirections UnobservableDirections(const ExtrinsicUncertainty& uncertainty,
                                      const JointAdjusterOptions& options) {
  HeldDirections held;
  for (int block = 0; block < 2; ++block) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(
        uncertainty.covariance.block<3, 3>(3 * block, 3 * block));
    const double threshold = block == 0 ? options.hold_rotation_deg : options.hold_translation_mm;
    for (int k = 0; k < 3; ++k) {
      const double sigma = std::sqrt(std::max(0.0, solver.eigenvalues()[k]));
      if (!(sigma > threshold)) continue;
      const Eigen::Vector3d direction = solver.eigenvectors().col(k);
      (block == 0 ? held.rotation : held.translation) += direction * direction.transpose();
      std::ostringstream name;
      name << std::fixed << std::setprecision(2)
           << (block == 0 ? "rotation about" : "translation along")
           << " the camera-frame direction (" << direction.x() << ", " << direction.y() << ", "
           << direction.z() << "), sigma " << std::setprecision(3) << sigma
           << (block == 0 ? " deg" : " mm");
      held.names.push_back(name.str());
    }
  }
  return held;
}

// The held pass's start: `start` with its components along the held directions taken from
// `guess` (rotation vectors of guess * inverse(start) about the camera axes, projected).
colmap::Rigid3d HeldAtGuess(const colmap::Rigid3d& start,
                            const colmap::Rigid3d& guess,
                            const HeldDirections& held) {
  const Eigen::AngleAxisd difference(guess.rotation * start.rotation.inverse());
  const Eigen::Vector3d rotation = held.rotation * (difference.angle() * difference.axis());
  colmap::Rigid3d result = start;
  result.rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(rotation.norm(), rotation.normalized())) *
                     start.rotation)
                        .normalized();
  result.translation += held.translation * (guess.translation - start.translation);
  return result;
}

}  // namespace

bool JointProblemData::HasExtrinsicPrior() const {
  return std::any_of(extrinsic_measurements.begin(),
                     extrinsic_measurements.end(),
                     [](const ExtrinsicMeasurement& measurement) { return measurement.prior; });
}

bool JointAdjusterOptions::Check() const {
  CHECK_OPTION_GT(sigma_lidar_m, 0);
  CHECK_OPTION_GE(depth_weight, 0);
  CHECK_OPTION_GE(first_depth_prior_round, 1);
  CHECK_OPTION_GE(lidar_weight, 0);
  CHECK_OPTION_GE(landmark_lidar_weight, 0);
  CHECK_OPTION_GT(sigma_landmark_lidar_m, 0);
  CHECK_OPTION_GT(max_landmark_plane_m, 0);
  CHECK_OPTION_GT(max_landmark_plane_sigmas, 0);
  CHECK_OPTION_GT(loss_scale, 0);
  CHECK_OPTION_GT(max_reprojection_error_px, 0);
  CHECK_OPTION_GT(max_depth_error_sigmas, 0);
  CHECK_OPTION_GE(max_depth_error_m, 0);
  CHECK_OPTION_GT(max_point_to_plane_m, 0);
  CHECK_OPTION_GE(max_outlier_iterations, 1);
  CHECK_OPTION_GE(num_association_rounds, 1);
  CHECK_OPTION_GE(initial_association_distance_m, association.max_distance);
  CHECK_OPTION_GT(max_num_iterations, 0);
  CHECK_OPTION_GE(extrinsic_prior_sigma_m, 0);
  CHECK_OPTION_GE(max_association_rounds, num_association_rounds);
  CHECK_OPTION_GT(round_convergence_deg, 0);
  CHECK_OPTION_GT(round_convergence_mm, 0);
  CHECK_OPTION_GT(hold_rotation_deg, 0);
  CHECK_OPTION_GT(hold_translation_mm, 0);
  CHECK_OPTION(association.Check());
  CHECK_OPTION(observability.Check());
  return true;
}

JointAdjuster::JointAdjuster(const JointAdjusterOptions& options) : options_(options) {
  THROW_CHECK(options_.Check());
}

JointAdjustmentSummary JointAdjuster::RunOnce(const JointProblemData& data,
                                              colmap::Reconstruction* reconstruction,
                                              colmap::Rigid3d* cam_from_lidar,
                                              const Eigen::Matrix3d& held_rotation,
                                              const Eigen::Matrix3d& held_translation) const {
  std::vector<colmap::image_t> image_ids = reconstruction->RegImageIds();
  std::sort(image_ids.begin(), image_ids.end());
  RunState state(options_, data, reconstruction, cam_from_lidar);
  state.held_rotation = held_rotation;
  state.held_translation = held_translation;
  state.lidar_free_axis = LidarFreeAxis(options_, *reconstruction);
  for (const colmap::image_t image_id : image_ids) state.config.AddImage(image_id);
  state.config.SetConstantCamPose(image_ids.front());  // the gauge

  JointAdjustmentSummary summary;
  Associations associations;
  const int num_rounds = state.UsesExtrinsic() ? options_.num_association_rounds : 1;
  bool factors_changed = false;
  for (int round = 0;
       round < num_rounds || RoundMovedExtrinsic(options_, summary) || factors_changed;
       ++round) {
    if (round >= options_.max_association_rounds) break;
    const colmap::Rigid3d before = *cam_from_lidar;
    state.depth_priors_in_force = !state.UsesExtrinsic() ||
                                  round + 1 >= options_.first_depth_prior_round ||
                                  num_rounds < options_.first_depth_prior_round;
    if (!state.depth_priors_in_force && options_.depth_weight > 0 && !data.depth_priors.empty()) {
      std::cout << "Round " << round + 1 << " without the depth priors (they join in round "
                << options_.first_depth_prior_round << ")" << std::endl;
    }
    if (state.UsesExtrinsic()) Reassociate(round, num_rounds, &state, &associations);
    SolveWithOutliers(round, &state, &associations, &summary);
    if (options_.estimate_variance_components) {
      summary.variance_components = UpdateVarianceFactors(&state, associations, &factors_changed);
    }
    summary.extrinsic_change_per_round.push_back(ExtrinsicChange(before, *cam_from_lidar));
    summary.last_round_move = ExtrinsicAxisMove(before, *cam_from_lidar);
    if (state.UsesExtrinsic()) {
      std::cout << "  round " << round + 1 << " moved cam_from_lidar by "
                << summary.extrinsic_change_per_round.back()[0] << " deg, "
                << summary.extrinsic_change_per_round.back()[1] << " mm" << std::endl;
    }
  }

  summary.association_settled =
      !state.UsesExtrinsic() || (!RoundMovedExtrinsic(options_, summary) && !factors_changed);
  // The uncertainty and the perturbation curves are evaluated on a problem rebuilt from the final
  // state: the last solve's problem may hold residuals of observations (even landmarks) removed after
  // it.
  summary.motion = AnalyseMotion(*reconstruction, options_.observability);
  RecordFinalState(state, data, associations, &summary);
  const std::unique_ptr<JointProblem> final_problem = BuildProblem(state, associations);
  summary.final_reprojection_residuals = final_problem->reprojection_ids.size();
  summary.final_depth_residuals = final_problem->depth_ids.size();
  summary.final_lidar_residuals = final_problem->num_lidar_residuals;
  summary.final_landmark_lidar_residuals = final_problem->landmark_ids.size();
  if (state.UsesExtrinsic()) {
    const auto start = std::chrono::steady_clock::now();
    summary.uncertainty = Uncertainty(state, *final_problem, summary.motion);
    summary.perturbation = PerturbationCurves(state, final_problem.get());
    std::cout << "Uncertainty and perturbation curves (" << SecondsSince(start) << " s)"
              << std::endl;
  }
  return summary;
}

JointAdjustmentSummary JointAdjuster::Run(const JointProblemData& data,
                                          colmap::Reconstruction* reconstruction,
                                          colmap::Rigid3d* cam_from_lidar) const {
  THROW_CHECK_NOTNULL(reconstruction);
  THROW_CHECK_NOTNULL(cam_from_lidar);
  THROW_CHECK_GE(reconstruction->NumRegImages(), 2)
      << "the joint problem needs at least 2 registered images";
  // With a prior, weak directions keep the prior's sigma instead of being held.
  const bool may_hold =
      options_.hold_unobservable && options_.mode == JointMode::kJoint && !data.HasExtrinsicPrior();
  const colmap::Reconstruction initial_reconstruction =
      may_hold ? *reconstruction : colmap::Reconstruction();
  const colmap::Rigid3d initial_extrinsic = *cam_from_lidar;
  JointAdjustmentSummary summary = RunOnce(
      data, reconstruction, cam_from_lidar, Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero());
  if (!may_hold || !summary.uncertainty.computed) return summary;
  const HeldDirections held = UnobservableDirections(summary.uncertainty, options_);
  if (held.names.empty()) return summary;
  const bool at_guess = data.cam_from_lidar_guess.has_value();
  std::cout << "cam_from_lidar: " << held.names.size()
            << " direction(s) unobservable; solving again from the start with them held at "
            << (at_guess ? "rig.json's guess" : "their initial value") << std::endl;
  *reconstruction = initial_reconstruction;
  *cam_from_lidar = at_guess ? HeldAtGuess(initial_extrinsic, *data.cam_from_lidar_guess, held)
                             : initial_extrinsic;
  JointAdjustmentSummary held_summary =
      RunOnce(data, reconstruction, cam_from_lidar, held.rotation, held.translation);
  held_summary.held_directions = held.names;
  held_summary.held_at_guess = at_guess;
  held_summary.solves.insert(
      held_summary.solves.begin(), summary.solves.begin(), summary.solves.end());
  return held_summary;
}

}  // namespace colmap_lidar
