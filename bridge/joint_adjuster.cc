#include "bridge/joint_adjuster.h"

#include "bridge/extrinsic_prior_cost.h"
#include "bridge/lidar_point_to_plane_cost.h"
#include "colmap_ext/depth_prior_cost.h"
#include "colmap_ext/logging.h"

#include "colmap/estimators/bundle_adjustment.h"
#include "colmap/estimators/cost_functions.h"
#include "colmap/scene/projection.h"

#include <ceres/ceres.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <set>

namespace colmap_lidar {
namespace {

using ImagePoint = std::pair<colmap::image_t, colmap::point2D_t>;

double TermCost(ceres::Problem* problem, const std::vector<ceres::ResidualBlockId>& ids) {
  if (ids.empty()) return 0;
  ceres::Problem::EvaluateOptions options;
  options.residual_blocks = ids;
  options.num_threads = 2;
  double cost = 0;
  problem->Evaluate(options, &cost, nullptr, nullptr, nullptr);
  return cost;
}

Eigen::Isometry3d ToIsometry(const colmap::Rigid3d& transform) {
  Eigen::Isometry3d isometry = Eigen::Isometry3d::Identity();
  isometry.linear() = transform.rotation.toRotationMatrix();
  isometry.translation() = transform.translation;
  return isometry;
}

// lidar_i_from_lidar_j = inverse(T_e) cam_i_from_world inverse(cam_j_from_world) T_e.
colmap::Rigid3d LidarIFromLidarJ(const colmap::Rigid3d& cam_i_from_world,
                                 const colmap::Rigid3d& cam_j_from_world,
                                 const colmap::Rigid3d& cam_from_lidar) {
  return colmap::Inverse(cam_from_lidar) * cam_i_from_world * colmap::Inverse(cam_j_from_world) *
         cam_from_lidar;
}

std::unique_ptr<ceres::LossFunction> MakeLoss(const std::string& name, double scale) {
  if (name == "huber") return std::make_unique<ceres::HuberLoss>(scale);
  if (name == "cauchy") return std::make_unique<ceres::CauchyLoss>(scale);
  return nullptr;
}

// The joint problem of one solve: COLMAP's bundle adjuster with our blocks injected.
struct JointProblem {
  std::unique_ptr<colmap::BundleAdjuster> adjuster;
  std::shared_ptr<ceres::Problem> problem;
  std::vector<ceres::ResidualBlockId> reprojection_ids;
  std::vector<ceres::ResidualBlockId> depth_ids;
  std::vector<ceres::ResidualBlockId> lidar_ids;
  std::vector<colmap::image_t> depth_images;    // parallel to depth_ids
  std::vector<double> depth_scale_derivatives;  // -d / sigma, parallel to depth_ids
  std::vector<ceres::ResidualBlockId> prior_ids;
  std::vector<std::pair<colmap::image_t, colmap::image_t>> lidar_pairs;  // parallel to lidar_ids
  colmap::BundleAdjustmentOptions ba_options;
};

// The depth prior of a landmark observation, unless it has none or was found an outlier.
const DepthPrior* FindDepthPrior(const JointProblemData& data,
                                 const std::set<ImagePoint>& outliers,
                                 const colmap::TrackElement& element) {
  const auto image_priors = data.depth_priors.find(element.image_id);
  if (image_priors == data.depth_priors.end()) return nullptr;
  const auto prior = image_priors->second.find(element.point2D_idx);
  if (prior == image_priors->second.end() ||
      outliers.count({element.image_id, element.point2D_idx})) {
    return nullptr;
  }
  return &prior->second;
}

}  // namespace

JointMode JointModeFromName(const std::string& name) {
  if (name == "joint") return JointMode::kJoint;
  if (name == "precalibrated") return JointMode::kPrecalibrated;
  if (name == "stereo_only") return JointMode::kStereoOnly;
  throw std::invalid_argument("unknown mode '" + name + "' (joint, precalibrated, stereo_only)");
}

std::string JointModeName(JointMode mode) {
  switch (mode) {
    case JointMode::kJoint:
      return "joint";
    case JointMode::kPrecalibrated:
      return "precalibrated";
    case JointMode::kStereoOnly:
      return "stereo_only";
  }
  return "";
}

bool JointAdjusterOptions::Check() const {
  CHECK_OPTION_GT(sigma_lidar_m, 0);
  CHECK_OPTION_GE(depth_weight, 0);
  CHECK_OPTION_GE(lidar_weight, 0);
  CHECK_OPTION(loss == "none" || loss == "huber" || loss == "cauchy");
  CHECK_OPTION_GT(loss_scale, 0);
  CHECK_OPTION_GT(max_reprojection_error_px, 0);
  CHECK_OPTION_GT(max_depth_error_m, 0);
  CHECK_OPTION_GT(max_point_to_plane_m, 0);
  CHECK_OPTION_GE(max_outlier_iterations, 1);
  CHECK_OPTION_GE(num_association_rounds, 1);
  CHECK_OPTION_GE(initial_association_distance_m, association.max_distance);
  CHECK_OPTION_GT(max_num_iterations, 0);
  CHECK_OPTION_GE(extrinsic_prior_sigma_m, 0);
  association.Check();
  observability.Check();
  return true;
}

JointAdjuster::JointAdjuster(const JointAdjusterOptions& options, const JointProblemData& data)
    : options_(options), data_(data) {
  THROW_CHECK(options_.Check());
}

std::vector<JointAdjuster::Observation> JointAdjuster::Associate(
    const colmap::Reconstruction& reconstruction,
    const colmap::Rigid3d& cam_from_lidar,
    double max_distance) const {
  std::vector<std::pair<colmap::image_t, colmap::image_t>> directed;
  for (const auto& [a, b] : data_.pairs) {
    if (!reconstruction.ExistsImage(a) || !reconstruction.ExistsImage(b) ||
        !reconstruction.Image(a).IsRegistered() || !reconstruction.Image(b).IsRegistered() ||
        !data_.clouds.count(a) || !data_.clouds.count(b)) {
      continue;
    }
    directed.emplace_back(a, b);
    directed.emplace_back(b, a);
  }
  std::vector<std::vector<Observation>> per_pair(directed.size());
#pragma omp parallel for schedule(dynamic)
  for (int k = 0; k < static_cast<int>(directed.size()); ++k) {
    const auto [target, source] = directed[k];
    const StationCloud& target_cloud = *data_.clouds.at(target);
    const StationCloud& source_cloud = *data_.clouds.at(source);
    AssociationOptions association = options_.association;
    association.max_distance = max_distance;
    association.seed = options_.association.seed + 7919 * k;
    const colmap::Rigid3d target_from_source =
        LidarIFromLidarJ(reconstruction.Image(target).CamFromWorld(),
                         reconstruction.Image(source).CamFromWorld(),
                         cam_from_lidar);
    for (const PointToPlaneObservation& observation :
         AssociatePointToPlane(source_cloud.cloud,
                               target_cloud.cloud,
                               *target_cloud.tree,
                               ToIsometry(target_from_source),
                               association,
                               &target_cloud.curvature)) {
      per_pair[k].push_back({target, source, observation, false});
    }
  }
  std::vector<Observation> observations;
  for (auto& pair : per_pair) {
    observations.insert(observations.end(), pair.begin(), pair.end());
  }
  return observations;
}

JointAdjustmentSummary JointAdjuster::Run(colmap::Reconstruction* reconstruction,
                                          colmap::Rigid3d* cam_from_lidar) {
  THROW_CHECK_NOTNULL(reconstruction);
  THROW_CHECK_NOTNULL(cam_from_lidar);
  std::vector<colmap::image_t> image_ids = reconstruction->RegImageIds();
  THROW_CHECK_GE(image_ids.size(), 2) << "the joint problem needs at least 2 "
                                         "registered images";
  std::sort(image_ids.begin(), image_ids.end());
  const bool use_lidar = options_.mode != JointMode::kStereoOnly && options_.lidar_weight > 0;
  const bool refine_extrinsic = options_.mode == JointMode::kJoint;
  double* extrinsic_rotation = cam_from_lidar->rotation.coeffs().data();
  double* extrinsic_translation = cam_from_lidar->translation.data();
  const Eigen::Vector3d initial_translation = cam_from_lidar->translation;

  // Losses are owned here (COLMAP's problem does not take ownership).
  const std::unique_ptr<ceres::LossFunction> loss = MakeLoss(options_.loss, options_.loss_scale);

  colmap::BundleAdjustmentConfig config;
  for (const colmap::image_t image_id : image_ids) config.AddImage(image_id);
  config.SetConstantCamPose(image_ids.front());  // the gauge

  JointAdjustmentSummary summary;
  std::set<ImagePoint> depth_outliers;
  size_t num_reprojection_outliers = 0;
  std::unique_ptr<JointProblem> last;

  const auto build = [&](const std::vector<Observation>& observations) {
    auto joint = std::make_unique<JointProblem>();
    colmap::BundleAdjustmentOptions& ba = joint->ba_options;
    ba.refine_focal_length = false;  // the rig is calibrated
    ba.refine_principal_point = false;
    ba.refine_extra_params = false;
    ba.print_summary = false;
    ba.solver_options.max_num_iterations = options_.max_num_iterations;
    ba.solver_options.function_tolerance = 1e-12;
    ba.solver_options.gradient_tolerance = 1e-14;
    ba.solver_options.parameter_tolerance = 1e-12;
    ba.solver_options.num_threads = omp_get_max_threads();
    joint->adjuster = std::make_unique<colmap::BundleAdjuster>(ba, config);
    joint->adjuster->SetUpProblem(reconstruction, loss.get());
    joint->problem = joint->adjuster->Problem();
    ceres::Problem* problem = joint->problem.get();
    problem->GetResidualBlocks(&joint->reprojection_ids);

    // Pose blocks that COLMAP did not add (constant poses are folded into its cost functions).
    const auto pose_blocks = [&](colmap::image_t image_id) {
      colmap::Rigid3d& pose = reconstruction->Image(image_id).CamFromWorld();
      double* rotation = pose.rotation.coeffs().data();
      double* translation = pose.translation.data();
      if (!problem->HasParameterBlock(rotation)) {
        problem->AddParameterBlock(rotation, 4);
        colmap::SetQuaternionManifold(problem, rotation);
        problem->AddParameterBlock(translation, 3);
        if (config.HasConstantCamPose(image_id)) {
          problem->SetParameterBlockConstant(rotation);
          problem->SetParameterBlockConstant(translation);
        }
      }
      return std::make_pair(rotation, translation);
    };

    // E_d: the seed's depth-prior residual, for every observation of every landmark with a prior.
    const double depth_scale = 1.0 / std::sqrt(std::max(options_.depth_weight, 1e-300));
    if (options_.depth_weight > 0) {
      for (const auto& [point3D_id, point3D] : reconstruction->Points3D()) {
        double* xyz = reconstruction->Point3D(point3D_id).xyz.data();
        for (const colmap::TrackElement& element : point3D.track.Elements()) {
          const DepthPrior* prior = FindDepthPrior(data_, depth_outliers, element);
          if (prior == nullptr) continue;
          const double sigma = prior->sigma * depth_scale;
          if (config.HasConstantCamPose(element.image_id)) {
            joint->depth_images.push_back(element.image_id);
            joint->depth_scale_derivatives.push_back(-prior->depth / sigma);
            joint->depth_ids.push_back(problem->AddResidualBlock(
                DepthPriorConstantPoseCostFunctor::Create(
                    reconstruction->Image(element.image_id).CamFromWorld(), prior->depth, sigma),
                loss.get(),
                xyz));
          } else {
            const auto [rotation, translation] = pose_blocks(element.image_id);
            joint->depth_images.push_back(element.image_id);
            joint->depth_scale_derivatives.push_back(-prior->depth / sigma);
            joint->depth_ids.push_back(
                problem->AddResidualBlock(DepthPriorCostFunctor::Create(prior->depth, sigma),
                                          loss.get(),
                                          rotation,
                                          translation,
                                          xyz));
          }
        }
      }
    }

    // E_l with the shared extrinsic block.
    if (use_lidar) {
      problem->AddParameterBlock(extrinsic_rotation, 4);
      colmap::SetQuaternionManifold(problem, extrinsic_rotation);
      problem->AddParameterBlock(extrinsic_translation, 3);
      if (!refine_extrinsic || options_.hold_rotation) {
        problem->SetParameterBlockConstant(extrinsic_rotation);
      }
      std::vector<int> held;
      for (int i = 0; i < 3; ++i) {
        if (options_.hold_translation[i]) held.push_back(i);
      }
      if (!refine_extrinsic || held.size() == 3) {
        problem->SetParameterBlockConstant(extrinsic_translation);
      } else if (!held.empty()) {
        colmap::SetSubsetManifold(3, held, problem, extrinsic_translation);
      }
      if (refine_extrinsic && held.size() < 3 && options_.extrinsic_prior_sigma_m > 0) {
        joint->prior_ids.push_back(
            problem->AddResidualBlock(ExtrinsicTranslationPriorCostFunctor::Create(
                                          initial_translation, options_.extrinsic_prior_sigma_m),
                                      nullptr,
                                      extrinsic_translation));
      }
      const double sigma = options_.sigma_lidar_m / std::sqrt(options_.lidar_weight);
      for (const Observation& observation : observations) {
        if (observation.outlier) continue;
        const auto [target_rotation, target_translation] = pose_blocks(observation.target);
        const auto [source_rotation, source_translation] = pose_blocks(observation.source);
        joint->lidar_pairs.emplace_back(observation.target, observation.source);
        joint->lidar_ids.push_back(problem->AddResidualBlock(
            LidarPointToPlaneCostFunctor::Create(observation.data.point_in_source,
                                                 observation.data.point_in_target,
                                                 observation.data.normal_in_target,
                                                 sigma),
            loss.get(),
            target_rotation,
            target_translation,
            source_rotation,
            source_translation,
            extrinsic_rotation,
            extrinsic_translation));
      }
    }
    return joint;
  };

  const int num_rounds = use_lidar ? options_.num_association_rounds : 1;
  for (int round = 0; round < num_rounds; ++round) {
    std::vector<Observation> observations;
    if (use_lidar) {
      const double gate = std::max(options_.association.max_distance,
                                   options_.initial_association_distance_m * std::pow(0.5, round));
      observations = Associate(*reconstruction, *cam_from_lidar, gate);
      std::cout << "Round " << round + 1 << "/" << num_rounds << ": " << observations.size()
                << " LiDAR point-to-plane observations (gate " << gate << " m)" << std::endl;
    }
    size_t num_lidar_outliers = 0;
    for (int iteration = 0; iteration < options_.max_outlier_iterations; ++iteration) {
      const auto start = std::chrono::steady_clock::now();
      last = build(observations);
      ceres::Problem* problem = last->problem.get();
      SolveStats stats;
      stats.round = round + 1;
      stats.outlier_iteration = iteration + 1;
      stats.reprojection.num_observations = last->reprojection_ids.size();
      stats.depth.num_observations = last->depth_ids.size();
      stats.lidar.num_observations = last->lidar_ids.size();
      stats.reprojection.cost_before = TermCost(problem, last->reprojection_ids);
      stats.depth.cost_before = TermCost(problem, last->depth_ids);
      stats.lidar.cost_before = TermCost(problem, last->lidar_ids);
      const ceres::Solver::Options solver_options =
          last->adjuster->SetUpSolverOptions(*problem, last->ba_options.solver_options);
      ceres::Solver::Summary solver_summary;
      ceres::Solve(solver_options, problem, &solver_summary);
      stats.reprojection.cost_after = TermCost(problem, last->reprojection_ids);
      stats.depth.cost_after = TermCost(problem, last->depth_ids);
      stats.lidar.cost_after = TermCost(problem, last->lidar_ids);
      stats.num_iterations = static_cast<int>(solver_summary.iterations.size());
      stats.termination = ceres::TerminationTypeToString(solver_summary.termination_type);

      // Outliers get weight zero: reprojection -> the observation leaves the reconstruction (as in
      // COLMAP's filtering); depth and LiDAR -> left out of the next build.
      size_t new_outliers = 0;
      const double max_squared_reprojection =
          options_.max_reprojection_error_px * options_.max_reprojection_error_px;
      std::vector<ImagePoint> bad_observations;
      for (const auto& [point3D_id, point3D] : reconstruction->Points3D()) {
        for (const colmap::TrackElement& element : point3D.track.Elements()) {
          const colmap::Image& image = reconstruction->Image(element.image_id);
          const double squared_error =
              colmap::CalculateSquaredReprojectionError(image.Point2D(element.point2D_idx).xy,
                                                        point3D.xyz,
                                                        image.CamFromWorld(),
                                                        reconstruction->Camera(image.CameraId()));
          if (squared_error > max_squared_reprojection) {
            bad_observations.emplace_back(element.image_id, element.point2D_idx);
            continue;
          }
          const DepthPrior* prior = FindDepthPrior(data_, depth_outliers, element);
          if (prior == nullptr) continue;
          const double depth = (image.CamFromWorld() * point3D.xyz).z();
          if (std::abs(depth - prior->depth) > options_.max_depth_error_m) {
            depth_outliers.insert({element.image_id, element.point2D_idx});
            ++new_outliers;
          }
        }
      }
      for (const ImagePoint& bad : bad_observations) {
        if (reconstruction->Image(bad.first).Point2D(bad.second).HasPoint3D()) {
          reconstruction->DeleteObservation(bad.first, bad.second);
          ++num_reprojection_outliers;
          ++new_outliers;
        }
      }
      for (Observation& observation : observations) {
        if (observation.outlier) continue;
        const colmap::Rigid3d target_from_source =
            LidarIFromLidarJ(reconstruction->Image(observation.target).CamFromWorld(),
                             reconstruction->Image(observation.source).CamFromWorld(),
                             *cam_from_lidar);
        const double distance = observation.data.normal_in_target.dot(
            target_from_source * observation.data.point_in_source -
            observation.data.point_in_target);
        if (std::abs(distance) > options_.max_point_to_plane_m) {
          observation.outlier = true;
          ++num_lidar_outliers;
          ++new_outliers;
        }
      }
      stats.reprojection.num_outliers = num_reprojection_outliers;
      stats.depth.num_outliers = depth_outliers.size();
      stats.lidar.num_outliers = num_lidar_outliers;
      stats.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::cout << std::defaultfloat << std::setprecision(4) << "  solve " << stats.round << "."
                << stats.outlier_iteration << ": cost reprojection "
                << stats.reprojection.cost_before << " -> " << stats.reprojection.cost_after
                << ", depth " << stats.depth.cost_before << " -> " << stats.depth.cost_after
                << ", lidar " << stats.lidar.cost_before << " -> " << stats.lidar.cost_after << "; "
                << stats.num_iterations << " iterations, " << new_outliers << " new outliers ("
                << std::setprecision(2) << stats.seconds << " s)" << std::endl;
      summary.solves.push_back(stats);
      if (new_outliers == 0) break;
    }
  }

  // Rebuild without the last outliers, evaluate uncertainty and the perturbation curves there.
  summary.motion = AnalyseMotion(*reconstruction, options_.observability);
  if (use_lidar) {
    ceres::Problem* problem = last->problem.get();
    // Clusters of residuals that share errors: a landmark's reprojections, an image's depth priors, a
    // directed LiDAR station pair.
    std::vector<std::vector<ceres::ResidualBlockId>> clusters;
    {
      std::unordered_map<const double*, size_t> landmark_cluster;
      for (const auto& [point3D_id, point3D] : reconstruction->Points3D()) {
        landmark_cluster.emplace(point3D.xyz.data(), landmark_cluster.size());
      }
      clusters.resize(landmark_cluster.size());
      std::vector<double*> blocks;
      for (const ceres::ResidualBlockId id : last->reprojection_ids) {
        problem->GetParameterBlocksForResidualBlock(id, &blocks);
        for (const double* block : blocks) {
          const auto it = landmark_cluster.find(block);
          if (it != landmark_cluster.end()) {
            clusters[it->second].push_back(id);
            break;
          }
        }
      }
      std::map<colmap::image_t, std::vector<ceres::ResidualBlockId>> per_image;
      for (size_t k = 0; k < last->depth_ids.size(); ++k) {
        per_image[last->depth_images[k]].push_back(last->depth_ids[k]);
      }
      std::map<std::pair<colmap::image_t, colmap::image_t>, std::vector<ceres::ResidualBlockId>>
          per_pair;
      for (size_t k = 0; k < last->lidar_ids.size(); ++k) {
        per_pair[last->lidar_pairs[k]].push_back(last->lidar_ids[k]);
      }
      for (auto& [image_id, ids] : per_image) clusters.push_back(std::move(ids));
      for (auto& [pair, ids] : per_pair) clusters.push_back(std::move(ids));
      clusters.push_back(last->prior_ids);
      clusters.erase(
          std::remove_if(
              clusters.begin(), clusters.end(), [](const auto& ids) { return ids.empty(); }),
          clusters.end());
    }
    std::unordered_map<ceres::ResidualBlockId, double> depth_scale_derivative;
    for (size_t k = 0; k < last->depth_ids.size(); ++k) {
      depth_scale_derivative[last->depth_ids[k]] = last->depth_scale_derivatives[k];
    }
    summary.uncertainty = ComputeExtrinsicUncertainty(problem,
                                                      extrinsic_rotation,
                                                      extrinsic_translation,
                                                      options_.hold_translation,
                                                      clusters,
                                                      depth_scale_derivative,
                                                      summary.motion,
                                                      options_.observability);
    if (last->reprojection_ids.empty() && last->depth_ids.empty()) {
      summary.uncertainty.unobservable.insert(
          summary.uncertainty.unobservable.begin(),
          "cam_from_lidar cannot be calibrated: no image landmark ties the "
          "cameras together, so the LiDAR fixes only the LiDAR poses and "
          "cam_from_lidar keeps its initial value; add overlapping images "
          "(more stations, or closer spacing)");
    }

    // The seed's perturbation curves: only E_l depends on T_e, so the total is the rest (constant) plus
    // the LiDAR term at the perturbed T_e.
    const double rest =
        TermCost(problem, last->reprojection_ids) + TermCost(problem, last->depth_ids);
    const colmap::Rigid3d optimum = *cam_from_lidar;
    static const char* kNames[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
    for (int dof = 0; dof < 6; ++dof) {
      PerturbationCurve curve;
      curve.parameter = kNames[dof];
      for (int step = -10; step <= 10; ++step) {
        const double offset = step * (dof < 3 ? 2.0 : 0.1);  // +-20 mm, +-1 deg
        *cam_from_lidar = optimum;
        if (dof < 3) {
          cam_from_lidar->translation[dof] += offset / 1000.0;
        } else {
          const Eigen::Vector3d axis = Eigen::Vector3d::Unit(dof - 3);
          cam_from_lidar->rotation =
              Eigen::Quaterniond(Eigen::AngleAxisd(offset * M_PI / 180, axis)) * optimum.rotation;
        }
        curve.offsets.push_back(offset);
        curve.costs.push_back(rest + TermCost(problem, last->lidar_ids));
      }
      summary.perturbation.push_back(curve);
    }
    *cam_from_lidar = optimum;
  }
  return summary;
}

}  // namespace colmap_lidar
