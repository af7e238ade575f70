#include "bridge/hand_eye.h"

#include "colmap_ext/logging.h"

#include <Eigen/Dense>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace colmap_lidar {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
}  // namespace

bool HandEyeOptions::Check() const {
  CHECK_OPTION_GT(min_rotation_deg, 0);
  CHECK_OPTION_GT(min_axis_angle_deg, 0);
  CHECK_OPTION_GT(max_axis_residual_deg, 0);
  return true;
}

HandEyeResult SolveHandEye(const std::vector<HandEyeMotion>& motions,
                           const HandEyeOptions& options) {
  THROW_CHECK(options.Check());
  HandEyeResult result;
  std::vector<Eigen::Vector3d> axes_a, axes_b;
  std::vector<double> weights;
  std::vector<const HandEyeMotion*> used;
  for (const HandEyeMotion& motion : motions) {
    const Eigen::AngleAxisd a(motion.cam_i_from_cam_j.rotation);
    const Eigen::AngleAxisd b(motion.lidar_i_from_lidar_j.rotation);
    if (a.angle() < options.min_rotation_deg * kDegToRad) continue;
    // A and B are conjugate: equal rotation angles.
    if (std::abs(a.angle() - b.angle()) > options.max_axis_residual_deg * kDegToRad) {
      continue;
    }
    axes_a.push_back(a.axis());
    axes_b.push_back(b.axis());
    weights.push_back(a.angle());
    used.push_back(&motion);
  }
  result.num_motions = static_cast<int>(used.size());
  for (size_t i = 0; i < axes_a.size(); ++i) {
    for (size_t j = i + 1; j < axes_a.size(); ++j) {
      result.max_axis_angle_deg =
          std::max(result.max_axis_angle_deg,
                   std::acos(std::min(1.0, std::abs(axes_a[i].dot(axes_a[j])))) / kDegToRad);
    }
  }
  std::ostringstream message;
  message << std::fixed << std::setprecision(1);
  if (used.size() < 2 || result.max_axis_angle_deg < options.min_axis_angle_deg) {
    message << "degenerate motion for hand-eye calibration: " << used.size()
            << " rotating motion pairs";
    if (!used.empty()) {
      message << ", rotation axes within " << result.max_axis_angle_deg
              << " deg (need >= 2 motions about non-parallel axes)";
    }
    result.message = message.str();
    return result;
  }

  // Rotation: weighted Kabsch, axes_a = R axes_b.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < axes_a.size(); ++k) {
    covariance += weights[k] * axes_a[k] * axes_b[k].transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  const Eigen::Matrix3d rotation = svd.matrixU() * d * svd.matrixV().transpose();
  double squared = 0;
  for (size_t k = 0; k < axes_a.size(); ++k) {
    squared += std::pow(std::acos(std::min(1.0, axes_a[k].dot(rotation * axes_b[k]))), 2);
  }
  result.rotation_rms_deg = std::sqrt(squared / axes_a.size()) / kDegToRad;

  // Translation: (R_A - I) t = R t_B - t_A.
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
  message << "hand-eye from " << used.size() << " motion pairs (axes span "
          << result.max_axis_angle_deg << " deg): axis fit " << std::setprecision(3)
          << result.rotation_rms_deg << " deg rms, translation residual "
          << 1000 * result.translation_rms_m << " mm rms";
  result.message = message.str();
  return result;
}

}  // namespace colmap_lidar
