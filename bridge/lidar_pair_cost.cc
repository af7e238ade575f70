#include "bridge/lidar_pair_cost.h"

#include "colmap_ext/logging.h"

#include <Eigen/Geometry>
#include <ceres/manifold.h>

namespace colmap_lidar {
namespace {

using RowVector3 = Eigen::Matrix<double, 1, 3>;

// Writes the ambient Jacobian of a quaternion block (row `row` of a [rows x 4] row-major matrix) from
// the derivative by the rotation vector of a left-multiplied perturbation (see the header).
void WriteQuaternionJacobian(const Eigen::Matrix<double, 4, 3>& plus_jacobian,
                             const Eigen::Vector3d& by_rotation_vector,
                             int row,
                             double* jacobian) {
  Eigen::Map<Eigen::Matrix<double, 1, 4>>(jacobian + 4 * row) =
      2.0 * by_rotation_vector.transpose() * plus_jacobian.transpose();
}

void WriteTranslationJacobian(const Eigen::Vector3d& derivative, int row, double* jacobian) {
  Eigen::Map<RowVector3>(jacobian + 3 * row) = derivative.transpose();
}

Eigen::Matrix<double, 4, 3> PlusJacobian(const double* quaternion) {
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> jacobian;
  ceres::EigenQuaternionManifold().PlusJacobian(quaternion, jacobian.data());
  return jacobian;
}

}  // namespace

LidarPairPointToPlaneCost::LidarPairPointToPlaneCost(
    std::vector<PointToPlaneObservation> observations, double sigma)
    : observations_(std::move(observations)), inverse_sigma_(1.0 / sigma) {
  THROW_CHECK(!observations_.empty());
  THROW_CHECK_GT(sigma, 0);
  set_num_residuals(static_cast<int>(observations_.size()));
  *mutable_parameter_block_sizes() = {4, 3, 4, 3, 4, 3};
}

ceres::CostFunction* LidarPairPointToPlaneCost::Create(
    std::vector<PointToPlaneObservation> observations, double sigma) {
  return new LidarPairPointToPlaneCost(std::move(observations), sigma);
}

// Per residual (camera i's frame, sigma omitted): a = R_e p + t_e, u = a - t_j, b = R_i R_j^T u + t_i,
// m = R_e n, g = R_j R_i^T m, r = m^T (b - R_e q - t_e). For left-multiplied rotation vectors w:
//   dr/dw_i = (b - t_i) x m,  dr/dt_i = m;   dr/dw_j = g x u,  dr/dt_j = -g;
//   dr/dw_e = m x (b - t_e) + (R_e p) x g,   dr/dt_e = g - m.
bool LidarPairPointToPlaneCost::Evaluate(double const* const* parameters,
                                         double* residuals,
                                         double** jacobians) const {
  const Eigen::Map<const Eigen::Quaterniond> rotation_i(parameters[0]);
  const Eigen::Map<const Eigen::Vector3d> translation_i(parameters[1]);
  const Eigen::Map<const Eigen::Quaterniond> rotation_j(parameters[2]);
  const Eigen::Map<const Eigen::Vector3d> translation_j(parameters[3]);
  const Eigen::Map<const Eigen::Quaterniond> rotation_e(parameters[4]);
  const Eigen::Map<const Eigen::Vector3d> translation_e(parameters[5]);
  const Eigen::Matrix3d r_i = rotation_i.toRotationMatrix();
  const Eigen::Matrix3d r_j = rotation_j.toRotationMatrix();
  const Eigen::Matrix3d r_e = rotation_e.toRotationMatrix();
  const Eigen::Matrix3d cam_i_from_cam_j = r_i * r_j.transpose();
  const bool any_jacobian = jacobians != nullptr;
  Eigen::Matrix<double, 4, 3> plus_i, plus_j, plus_e;
  if (any_jacobian && jacobians[0]) plus_i = PlusJacobian(parameters[0]);
  if (any_jacobian && jacobians[2]) plus_j = PlusJacobian(parameters[2]);
  if (any_jacobian && jacobians[4]) plus_e = PlusJacobian(parameters[4]);

  for (int k = 0; k < static_cast<int>(observations_.size()); ++k) {
    const PointToPlaneObservation& observation = observations_[k];
    const Eigen::Vector3d rotated_p = r_e * observation.point_in_source;
    const Eigen::Vector3d u = rotated_p + translation_e - translation_j;
    const Eigen::Vector3d b = cam_i_from_cam_j * u + translation_i;
    const Eigen::Vector3d m = r_e * observation.normal_in_target * inverse_sigma_;
    residuals[k] = m.dot(b - r_e * observation.point_in_target - translation_e);
    if (!any_jacobian) continue;
    const Eigen::Vector3d g = cam_i_from_cam_j.transpose() * m;
    if (jacobians[0])
      WriteQuaternionJacobian(plus_i, (b - translation_i).cross(m), k, jacobians[0]);
    if (jacobians[1]) WriteTranslationJacobian(m, k, jacobians[1]);
    if (jacobians[2]) WriteQuaternionJacobian(plus_j, g.cross(u), k, jacobians[2]);
    if (jacobians[3]) WriteTranslationJacobian(-g, k, jacobians[3]);
    if (jacobians[4]) {
      WriteQuaternionJacobian(
          plus_e, m.cross(b - translation_e) + rotated_p.cross(g), k, jacobians[4]);
    }
    if (jacobians[5]) WriteTranslationJacobian(g - m, k, jacobians[5]);
  }
  return true;
}

}  // namespace colmap_lidar
