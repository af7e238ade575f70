#include "bridge/initialization/hand_eye.h"

#include "colmap_ext/logging.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numeric>
#include <sstream>
#include <tuple>

namespace colmap_lidar {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
// A motion translating less carries no translation direction [m].
constexpr double kMinTranslationM = 0.1;
constexpr int kMaxPlanarRounds = 50;
}  // namespace

bool HandEyeOptions::Check() const {
  CHECK_OPTION_GT(min_rotation_deg, 0);
  CHECK_OPTION_GT(min_axis_angle_deg, 0);
  CHECK_OPTION_GT(max_axis_residual_deg, 0);
  CHECK_OPTION_GT(max_motion_residual_deg, 0);
  return true;
}

namespace {

// Rotation axes of the motions that rotate enough and whose two rotation angles agree (A and B are
// conjugate), weighted by the angle.
struct RotationAxes {
  std::vector<Eigen::Vector3d> in_cam, in_lidar;
  std::vector<double> weights;
  std::vector<const HandEyeMotion*> motions;
};

RotationAxes RotatingMotions(const std::vector<HandEyeMotion>& motions,
                             const HandEyeOptions& options) {
  RotationAxes axes;
  for (const HandEyeMotion& motion : motions) {
    const Eigen::AngleAxisd a(motion.cam_i_from_cam_j.rotation);
    const Eigen::AngleAxisd b(motion.lidar_i_from_lidar_j.rotation);
    if (a.angle() < options.min_rotation_deg * kDegToRad) continue;
    if (std::abs(a.angle() - b.angle()) > options.max_axis_residual_deg * kDegToRad) continue;
    axes.in_cam.push_back(a.axis());
    axes.in_lidar.push_back(b.axis());
    axes.weights.push_back(a.angle());
    axes.motions.push_back(&motion);
  }
  return axes;
}

double MaxAngleBetweenLinesDeg(const std::vector<Eigen::Vector3d>& directions) {
  double max_angle = 0;
  for (size_t i = 0; i < directions.size(); ++i) {
    for (size_t j = i + 1; j < directions.size(); ++j) {
      max_angle =
          std::max(max_angle, std::acos(std::min(1.0, std::abs(directions[i].dot(directions[j])))));
    }
  }
  return max_angle / kDegToRad;
}

// The rotation R minimising sum w_k |in_cam_k - R in_lidar_k|^2 (weighted Kabsch).
Eigen::Matrix3d WeightedKabsch(const RotationAxes& axes) {
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < axes.in_cam.size(); ++k) {
    covariance += axes.weights[k] * axes.in_cam[k] * axes.in_lidar[k].transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

double AxisFitRmsDeg(const RotationAxes& axes, const Eigen::Matrix3d& rotation) {
  double squared = 0;
  for (size_t k = 0; k < axes.in_cam.size(); ++k) {
    squared +=
        std::pow(std::acos(std::min(1.0, axes.in_cam[k].dot(rotation * axes.in_lidar[k]))), 2);
  }
  return axes.in_cam.empty() ? 0.0 : std::sqrt(squared / axes.in_cam.size()) / kDegToRad;
}

std::string DegenerateMessage(size_t num_rotating, double max_axis_angle_deg) {
  std::ostringstream message;
  message << std::fixed << std::setprecision(1)
          << "degenerate motion for hand-eye calibration: " << num_rotating
          << " rotating motion pairs";
  if (num_rotating > 0) {
    message << ", rotation axes within " << max_axis_angle_deg
            << " deg (need >= 2 motions about non-parallel axes)";
  }
  return message.str();
}

// Translation directions of the motions that hardly rotate, as extra direction pairs for the rotation:
// a / |a| = R_X (t_B - R_X^T (R_A - I) t_X) / |...|, with the current estimate of R_X and t_X (the
// correction is small for a small rotation and vanishes at t_X = 0).
void AddTranslationDirections(const std::vector<HandEyeMotion>& motions,
                              const HandEyeOptions& options,
                              const colmap::Rigid3d& cam_from_lidar,
                              RotationAxes* axes) {
  for (const HandEyeMotion& motion : motions) {
    const Eigen::AngleAxisd a(motion.cam_i_from_cam_j.rotation);
    const Eigen::Vector3d& t_a = motion.cam_i_from_cam_j.translation;
    const Eigen::Vector3d t_b =
        motion.lidar_i_from_lidar_j.translation -
        cam_from_lidar.rotation.inverse() *
            ((a.toRotationMatrix() - Eigen::Matrix3d::Identity()) * cam_from_lidar.translation);
    if (a.angle() >= options.min_rotation_deg * kDegToRad || t_a.norm() == 0 ||
        t_b.norm() < kMinTranslationM) {
      continue;
    }
    axes->in_cam.push_back(t_a.normalized());
    axes->in_lidar.push_back(t_b.normalized());
    axes->weights.push_back(1.0);
  }
}

// (R_A - I) t_X + s a = R_X t_B over every motion, for t_X and s given R_X. With a non-zero `axis`,
// t_X's component along it is not solved for but taken from `fallback`.
Eigen::Vector3d SolveTranslationAndScale(const std::vector<HandEyeMotion>& motions,
                                         const Eigen::Matrix3d& rotation,
                                         const Eigen::Vector3d& axis,
                                         const Eigen::Vector3d& fallback,
                                         bool per_motion_scale,
                                         HandEyeResult* result) {
  const bool planar = axis.squaredNorm() > 0;
  Eigen::Matrix3d basis = Eigen::Matrix3d::Identity();
  int num_free = 3;
  if (planar) {
    const Eigen::Vector3d u = axis.unitOrthogonal();
    basis << u, axis.cross(u), Eigen::Vector3d::Zero();
    num_free = 2;
  }
  const Eigen::Vector3d fixed_part = axis * axis.dot(fallback);
  const int num_scales = per_motion_scale ? static_cast<int>(motions.size()) : 1;
  Eigen::MatrixXd lhs = Eigen::MatrixXd::Zero(3 * motions.size(), num_free + num_scales);
  Eigen::VectorXd rhs(3 * motions.size());
  for (size_t k = 0; k < motions.size(); ++k) {
    const colmap::Rigid3d& a = motions[k].cam_i_from_cam_j;
    const Eigen::Matrix3d r_a_minus_i = a.rotation.toRotationMatrix() - Eigen::Matrix3d::Identity();
    lhs.block(3 * k, 0, 3, num_free) = r_a_minus_i * basis.leftCols(num_free);
    lhs.block<3, 1>(3 * k, num_free + (per_motion_scale ? k : 0)) = a.translation;
    rhs.segment<3>(3 * k) =
        rotation * motions[k].lidar_i_from_lidar_j.translation - r_a_minus_i * fixed_part;
  }
  const Eigen::VectorXd solution = lhs.colPivHouseholderQr().solve(rhs);
  // The mean scale; -1 when a motion's scale is not positive (an inconsistent motion). Per motion,
  // only the motions that translate by kMinTranslationM count: the scale of a standstill is noise.
  std::vector<double> scales;
  for (int k = 0; k < num_scales; ++k) {
    if (!per_motion_scale ||
        motions[k].lidar_i_from_lidar_j.translation.norm() >= kMinTranslationM) {
      scales.push_back(solution(num_free + k));
    }
  }
  const bool positive = !scales.empty() && *std::min_element(scales.begin(), scales.end()) > 0;
  result->scale =
      positive ? std::accumulate(scales.begin(), scales.end(), 0.0) / scales.size() : -1;
  result->translation_rms_m = std::sqrt((lhs * solution - rhs).squaredNorm() / rhs.size());
  return basis.leftCols(num_free) * solution.head(num_free) + fixed_part;
}

}  // namespace

HandEyeResult SolveHandEye(const std::vector<HandEyeMotion>& motions,
                           const HandEyeOptions& options) {
  THROW_CHECK(options.Check());
  HandEyeResult result;
  const RotationAxes axes = RotatingMotions(motions, options);
  result.num_motions = static_cast<int>(axes.motions.size());
  result.max_axis_angle_deg = MaxAngleBetweenLinesDeg(axes.in_cam);
  if (axes.motions.size() < 2 || result.max_axis_angle_deg < options.min_axis_angle_deg) {
    result.message = DegenerateMessage(axes.motions.size(), result.max_axis_angle_deg);
    return result;
  }
  const Eigen::Matrix3d rotation = WeightedKabsch(axes);
  result.rotation_rms_deg = AxisFitRmsDeg(axes, rotation);

  // Translation: (R_A - I) t = R t_B - t_A.
  const std::vector<const HandEyeMotion*>& used = axes.motions;
  Eigen::MatrixXd lhs(3 * used.size(), 3);
  Eigen::VectorXd rhs(3 * used.size());
  for (size_t k = 0; k < used.size(); ++k) {
    const colmap::Rigid3d& a = used[k]->cam_i_from_cam_j;
    const colmap::Rigid3d& b = used[k]->lidar_i_from_lidar_j;
    lhs.block<3, 3>(3 * k, 0) = a.rotation.toRotationMatrix() - Eigen::Matrix3d::Identity();
    rhs.segment<3>(3 * k) = rotation * b.translation - a.translation;
  }
  const Eigen::Vector3d translation = lhs.colPivHouseholderQr().solve(rhs);
  result.translation_rms_m = std::sqrt((lhs * translation - rhs).squaredNorm() / rhs.size());
  result.cam_from_lidar = colmap::Rigid3d(Eigen::Quaterniond(rotation), translation);
  result.unique = true;
  result.rotation_unique = true;
  std::ostringstream message;
  message << std::fixed << std::setprecision(1) << "hand-eye from " << used.size()
          << " motion pairs (axes span " << result.max_axis_angle_deg << " deg): axis fit "
          << std::setprecision(3) << result.rotation_rms_deg << " deg rms, translation residual "
          << 1000 * result.translation_rms_m << " mm rms";
  result.message = message.str();
  return result;
}

namespace {

// The similarity hand-eye on consistent motions, as general motion or, with `planar`, as rotation about
// one axis (mean of the rotation axes, plus the translation directions of the motions that hardly
// rotate; the translation along the axis from the fallback).
HandEyeResult SimilarityHandEye(const std::vector<HandEyeMotion>& motions,
                                const HandEyeOptions& options,
                                const Eigen::Vector3d& axis_translation_fallback,
                                bool per_motion_scale,
                                bool planar) {
  HandEyeResult result;
  RotationAxes axes = RotatingMotions(motions, options);
  result.num_motions = static_cast<int>(axes.motions.size());
  result.max_axis_angle_deg = MaxAngleBetweenLinesDeg(axes.in_cam);
  // No turn left to give the axis (the last one left out as contradicting the fit): degenerate, not a
  // fit about a zero axis.
  if (planar && axes.motions.empty()) {
    result.message = DegenerateMessage(0, 0) + " (the turns contradict the fit)";
    return result;
  }
  if (planar) {
    Eigen::Vector3d mean_axis = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < axes.in_cam.size(); ++k) {
      const double sign = axes.in_cam[k].dot(axes.in_cam.front()) < 0 ? -1.0 : 1.0;
      mean_axis += sign * axes.weights[k] * axes.in_cam[k];
    }
    result.unobservable_axis_in_cam = mean_axis.normalized();
    RotationAxes with_directions = axes;
    AddTranslationDirections(motions, options, colmap::Rigid3d(), &with_directions);
    if (MaxAngleBetweenLinesDeg(with_directions.in_cam) < options.min_axis_angle_deg) {
      result.message = DegenerateMessage(axes.motions.size(), result.max_axis_angle_deg) +
                       ", and no translation across the axis";
      return result;
    }
  }
  // Planar: the direction pairs depend on t_X; rounds until the rotation settles (the correction is
  // small: three rounds left 3e-5 rad).
  const Eigen::Vector3d axis = result.unobservable_axis_in_cam;
  const RotationAxes rotating = axes;
  for (int round = 0; round < (planar ? kMaxPlanarRounds : 1); ++round) {
    axes = rotating;
    if (planar) AddTranslationDirections(motions, options, result.cam_from_lidar, &axes);
    const Eigen::Quaterniond rotation(WeightedKabsch(axes));
    const double change = rotation.angularDistance(result.cam_from_lidar.rotation);
    result.rotation_rms_deg = AxisFitRmsDeg(axes, rotation.toRotationMatrix());
    result.cam_from_lidar = colmap::Rigid3d(rotation,
                                            SolveTranslationAndScale(motions,
                                                                     rotation.toRotationMatrix(),
                                                                     axis,
                                                                     axis_translation_fallback,
                                                                     per_motion_scale,
                                                                     &result));
    if (round > 0 && change < 1e-12) break;
  }
  // Planar with translation directions only: the forward translation is confounded with the motions'
  // own scales (a car drives mostly straight), so no component of t_X is trusted: all from the fallback.
  if (planar && per_motion_scale) result.cam_from_lidar.translation = axis_translation_fallback;
  // A general fit must explain the axes; a planar one mixes axes and directions of small motions.
  result.rotation_unique =
      result.scale > 0 && (planar || result.rotation_rms_deg <= options.max_axis_residual_deg);
  result.unique = result.rotation_unique && !planar;
  return result;
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kDegToRad;
}

// The angle [deg] between the camera's rotation axis of `motion` and the rotated LiDAR axis; 0 if it
// rotates too little to have an axis.
double AxisResidualDeg(const HandEyeMotion& motion,
                       const HandEyeOptions& options,
                       const colmap::Rigid3d& cam_from_lidar) {
  const Eigen::AngleAxisd a(motion.cam_i_from_cam_j.rotation);
  if (a.angle() < options.min_rotation_deg * kDegToRad) return 0;
  const Eigen::AngleAxisd b(motion.lidar_i_from_lidar_j.rotation);
  return AngleDeg(a.axis(), cam_from_lidar.rotation * b.axis());
}

// The angle [deg] by which `motion` contradicts `cam_from_lidar`: between the camera's rotation axis
// and the rotated LiDAR axis (if it rotates enough), and between the camera's translation direction
// and the one the LiDAR motion predicts, s a = R_X t_B - (R_A - I) t_X (if it translates enough); the
// larger of the two, 0 when it says neither. With `axis_protected` the axis does not count.
double MotionResidualDeg(const HandEyeMotion& motion,
                         const HandEyeOptions& options,
                         const colmap::Rigid3d& cam_from_lidar,
                         bool axis_protected) {
  const Eigen::AngleAxisd a(motion.cam_i_from_cam_j.rotation);
  double residual = axis_protected ? 0.0 : AxisResidualDeg(motion, options, cam_from_lidar);
  const Eigen::Vector3d& t_a = motion.cam_i_from_cam_j.translation;
  const Eigen::Vector3d& t_b = motion.lidar_i_from_lidar_j.translation;
  if (t_b.norm() >= kMinTranslationM && t_a.norm() > 0) {
    const Eigen::Vector3d predicted =
        cam_from_lidar.rotation * t_b -
        (a.toRotationMatrix() - Eigen::Matrix3d::Identity()) * cam_from_lidar.translation;
    residual = std::max(residual, AngleDeg(t_a, predicted));
  }
  return residual;
}

// The motion that contradicts a fit most: `index` -1 if none.
struct Contradiction {
  int index = -1;
  // Left out for its axis alone (the general fit's axes do not fit one rotation).
  bool by_axis = false;
};

// The largest MotionResidualDeg if above options.max_motion_residual_deg (axes not counted when
// `axes_protected`); else, if `by_axis_allowed` and a general fit's axes do not fit one rotation
// (rotation_rms_deg above options.max_axis_residual_deg), the largest AxisResidualDeg.
Contradiction MostContradictingMotion(const std::vector<HandEyeMotion>& motions,
                                      const HandEyeOptions& options,
                                      const HandEyeResult& result,
                                      bool planar,
                                      bool by_axis_allowed,
                                      bool axes_protected) {
  Contradiction worst, worst_axis{-1, true};
  double worst_deg = options.max_motion_residual_deg, worst_axis_deg = 0;
  for (size_t k = 0; k < motions.size(); ++k) {
    const double residual =
        MotionResidualDeg(motions[k], options, result.cam_from_lidar, axes_protected);
    if (residual > worst_deg) std::tie(worst.index, worst_deg) = std::make_pair(int(k), residual);
    const double axis = AxisResidualDeg(motions[k], options, result.cam_from_lidar);
    if (axis > worst_axis_deg)
      std::tie(worst_axis.index, worst_axis_deg) = std::make_pair(int(k), axis);
  }
  const bool axes_fit = planar || result.rotation_rms_deg <= options.max_axis_residual_deg;
  return worst.index >= 0 || axes_fit || !by_axis_allowed ? worst : worst_axis;
}

// SimilarityHandEye, leaving out the motion that contradicts the fit most (MostContradictingMotion)
// and fitting again, until none does. A wrong two-view geometry (a flipped translation direction of
// forward motion) otherwise gives a negative scale or a wrong axis; one poorly estimated axis among
// tripod stations that rotate about distinct axes would otherwise send the fit to the planar
// variant, whose translation is 0. Only one motion is left out for its axis alone: the
// noisy axes of a car's small turns must not be thinned until a few happen to fit. Fails
// (rotation_unique false) when more than half of the motions would be left out, or when a general
// fit's remaining axes are parallel. A planar fit keeps at least half of its rotating motions: the
// axes of a drive's small turns from two-view geometries scatter widely, and leaving them out worst
// first could leave none; the rest are then judged by their translation directions only.
HandEyeResult FitWithoutContradictingMotions(std::vector<HandEyeMotion> motions,
                                             const HandEyeOptions& options,
                                             const Eigen::Vector3d& axis_translation_fallback,
                                             bool per_motion_scale,
                                             bool planar) {
  const size_t num_given = motions.size();
  const size_t num_rotating_given = RotatingMotions(motions, options).motions.size();
  bool left_out_by_axis = false;
  for (int left_out = 0;; ++left_out) {
    HandEyeResult result =
        SimilarityHandEye(motions, options, axis_translation_fallback, per_motion_scale, planar);
    result.num_contradicting = left_out;
    result.axis_misfit_left_out = left_out_by_axis;
    if (!result.message.empty()) return result;  // degenerate
    const bool axes_protected =
        planar && 2 * RotatingMotions(motions, options).motions.size() < num_rotating_given + 2;
    const Contradiction worst = MostContradictingMotion(
        motions, options, result, planar, !left_out_by_axis, axes_protected);
    if (worst.index < 0) return result;
    if (2 * static_cast<size_t>(left_out + 1) > num_given) {
      result.rotation_unique = result.unique = false;
      return result;
    }
    left_out_by_axis = left_out_by_axis || worst.by_axis;
    motions.erase(motions.begin() + worst.index);
    const RotationAxes axes = RotatingMotions(motions, options);
    if (!planar && (axes.motions.size() < 2 ||
                    MaxAngleBetweenLinesDeg(axes.in_cam) < options.min_axis_angle_deg)) {
      result.rotation_unique = result.unique = false;
      return result;
    }
  }
}

std::string SimilarityMessage(const HandEyeResult& result,
                              size_t num_used,
                              size_t num_given,
                              bool planar,
                              bool per_motion_scale,
                              const HandEyeOptions& options) {
  std::ostringstream message;
  message << std::fixed << std::setprecision(1) << "similarity hand-eye from "
          << num_used - result.num_contradicting << " of " << num_given << " motion pairs (";
  const int num_far = result.num_contradicting - (result.axis_misfit_left_out ? 1 : 0);
  if (num_far > 0) {
    message << num_far << " contradicting the fit by more than " << options.max_motion_residual_deg
            << " deg left out, ";
  }
  if (result.axis_misfit_left_out) {
    message << "1 whose axis kept the fit above " << options.max_axis_residual_deg
            << " deg rms left out, ";
  }
  message << result.num_motions << " rotating, axes span " << result.max_axis_angle_deg
          << " deg): scale " << std::setprecision(4) << result.scale << ", axis fit "
          << std::setprecision(3) << result.rotation_rms_deg << " deg rms, translation residual "
          << 1000 * result.translation_rms_m << " mm rms";
  if (!result.rotation_unique) {
    message << "; inconsistent motions ("
            << (result.num_contradicting > 0 && 2 * result.num_contradicting + 2 > num_used
                    ? "more than half contradict the fit"
                : result.scale > 0 ? "the axes do not fit one rotation"
                                   : "no positive scale")
            << ")";
  } else if (planar) {
    message << "; rotation about one axis only (camera " << std::setprecision(2)
            << result.unobservable_axis_in_cam.transpose() << "): the translation "
            << (per_motion_scale ? "is" : "along it is")
            << " not observable from motion and comes from the guess (or 0)";
  }
  return message.str();
}

}  // namespace

HandEyeResult SolveSimilarityHandEye(const std::vector<HandEyeMotion>& all_motions,
                                     const HandEyeOptions& options,
                                     const Eigen::Vector3d& axis_translation_fallback,
                                     bool per_motion_scale) {
  THROW_CHECK(options.Check());
  // A monocular model can be locally wrong (forward motion): motions whose camera and LiDAR rotation
  // angles disagree are left out altogether.
  std::vector<HandEyeMotion> motions;
  for (const HandEyeMotion& motion : all_motions) {
    if (std::abs(Eigen::AngleAxisd(motion.cam_i_from_cam_j.rotation).angle() -
                 Eigen::AngleAxisd(motion.lidar_i_from_lidar_j.rotation).angle()) <=
        options.max_axis_residual_deg * kDegToRad) {
      motions.push_back(motion);
    }
  }
  const RotationAxes axes = RotatingMotions(motions, options);
  if (axes.motions.empty()) {
    HandEyeResult result;
    result.message = DegenerateMessage(0, 0);
    return result;
  }
  // Planar when the axes are parallel, or when they do not fit one general rotation (the noisy axes of
  // a car's small turns).
  bool planar =
      axes.motions.size() < 2 || MaxAngleBetweenLinesDeg(axes.in_cam) < options.min_axis_angle_deg;
  HandEyeResult result = FitWithoutContradictingMotions(
      motions, options, axis_translation_fallback, per_motion_scale, planar);
  if (!planar && !result.rotation_unique) {
    planar = true;
    result = FitWithoutContradictingMotions(
        motions, options, axis_translation_fallback, per_motion_scale, true);
  }
  if (result.message.empty()) {
    result.message = SimilarityMessage(
        result, motions.size(), all_motions.size(), planar, per_motion_scale, options);
  }
  return result;
}

double HandEyeScale(const std::vector<HandEyeMotion>& motions,
                    const colmap::Rigid3d& cam_from_lidar) {
  double numerator = 0, denominator = 0;
  for (const HandEyeMotion& motion : motions) {
    const colmap::Rigid3d& a = motion.cam_i_from_cam_j;
    const Eigen::Vector3d metric =
        cam_from_lidar.rotation * motion.lidar_i_from_lidar_j.translation -
        (a.rotation.toRotationMatrix() - Eigen::Matrix3d::Identity()) * cam_from_lidar.translation;
    numerator += a.translation.dot(metric);
    denominator += a.translation.squaredNorm();
  }
  if (!(denominator > 0) || !(numerator > 0)) {
    throw std::runtime_error(
        "cannot scale the camera model to metres: no camera motion with a LiDAR motion translates");
  }
  return numerator / denominator;
}

}  // namespace colmap_lidar
