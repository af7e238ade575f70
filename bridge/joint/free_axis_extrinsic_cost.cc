#include "bridge/joint/free_axis_extrinsic_cost.h"

#include "colmap_ext/logging.h"

#include <Eigen/Geometry>

#include <vector>

namespace colmap_lidar {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// L with (a * q).coeffs() = L q.coeffs() for every quaternion q (Hamilton product, x y z w).
Eigen::Matrix4d LeftProductMatrix(const Eigen::Quaterniond& a) {
  Eigen::Matrix4d left;
  for (int k = 0; k < 4; ++k) {
    Eigen::Quaterniond basis;
    basis.coeffs() = Eigen::Vector4d::Unit(k);
    left.col(k) = (a * basis).coeffs();
  }
  return left;
}

}  // namespace

FreeAxisExtrinsicCost::FreeAxisExtrinsicCost(ceres::CostFunction* inner,
                                             const Eigen::Vector3d& axis_in_cam)
    : inner_(inner),
      axis_(axis_in_cam.normalized()),
      num_inner_blocks_(static_cast<int>(inner->parameter_block_sizes().size())) {
  THROW_CHECK_GE(num_inner_blocks_, 2);
  THROW_CHECK_EQ(inner->parameter_block_sizes()[num_inner_blocks_ - 2], 4);
  THROW_CHECK_EQ(inner->parameter_block_sizes()[num_inner_blocks_ - 1], 3);
  THROW_CHECK_GT(axis_in_cam.norm(), 0);
  *mutable_parameter_block_sizes() = inner->parameter_block_sizes();
  mutable_parameter_block_sizes()->push_back(1);
  set_num_residuals(inner->num_residuals());
}

ceres::CostFunction* FreeAxisExtrinsicCost::Create(ceres::CostFunction* inner,
                                                   const Eigen::Vector3d& axis_in_cam) {
  return new FreeAxisExtrinsicCost(inner, axis_in_cam);
}

bool FreeAxisExtrinsicCost::Evaluate(double const* const* parameters,
                                     double* residuals,
                                     double** jacobians) const {
  const int rotation = num_inner_blocks_ - 2, translation = num_inner_blocks_ - 1;
  const double angle = parameters[num_inner_blocks_][0];
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(angle, axis_));
  const Eigen::Map<const Eigen::Quaterniond> extrinsic_rotation(parameters[rotation]);
  const Eigen::Map<const Eigen::Vector3d> extrinsic_translation(parameters[translation]);
  // exp(rho u) * T_e: both the rotation and the translation turn.
  const Eigen::Quaterniond turned_rotation = turn * extrinsic_rotation;
  const Eigen::Vector3d turned_translation = turn * extrinsic_translation;
  std::vector<const double*> inner_parameters(parameters, parameters + num_inner_blocks_);
  inner_parameters[rotation] = turned_rotation.coeffs().data();
  inner_parameters[translation] = turned_translation.data();
  if (jacobians == nullptr) {
    return inner_->Evaluate(inner_parameters.data(), residuals, nullptr);
  }
  const int m = num_residuals();
  RowMajorMatrix rotation_jacobian(m, 4), translation_jacobian(m, 3);
  std::vector<double*> inner_jacobians(jacobians, jacobians + num_inner_blocks_);
  inner_jacobians[rotation] = rotation_jacobian.data();
  inner_jacobians[translation] = translation_jacobian.data();
  if (!inner_->Evaluate(inner_parameters.data(), residuals, inner_jacobians.data())) return false;
  if (jacobians[rotation] != nullptr) {
    Eigen::Map<RowMajorMatrix>(jacobians[rotation], m, 4) =
        rotation_jacobian * LeftProductMatrix(turn);
  }
  if (jacobians[translation] != nullptr) {
    Eigen::Map<RowMajorMatrix>(jacobians[translation], m, 3) =
        translation_jacobian * turn.toRotationMatrix();
  }
  if (jacobians[num_inner_blocks_] != nullptr) {
    // d(turn)/d(rho) = (u cos(rho/2) / 2, -sin(rho/2) / 2) (x y z w); d(turned t)/d(rho) = u x t'.
    Eigen::Quaterniond turn_derivative;
    turn_derivative.vec() = 0.5 * std::cos(0.5 * angle) * axis_;
    turn_derivative.w() = -0.5 * std::sin(0.5 * angle);
    Eigen::Map<Eigen::VectorXd>(jacobians[num_inner_blocks_], m) =
        rotation_jacobian * (turn_derivative * extrinsic_rotation).coeffs() +
        translation_jacobian * axis_.cross(turned_translation);
  }
  return true;
}

}  // namespace colmap_lidar
