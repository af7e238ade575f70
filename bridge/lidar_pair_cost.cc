#include "bridge/lidar_pair_cost.h"

#include "colmap_ext/logging.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <ceres/manifold.h>

namespace colmap_lidar {
namespace {

constexpr int kTangentSize = 18;  // 3 per parameter block
constexpr int kAmbientSizes[6] = {4, 3, 4, 3, 4, 3};

using TangentRows = Eigen::Matrix<double, Eigen::Dynamic, kTangentSize, Eigen::RowMajor>;

Eigen::Matrix<double, 4, 3> PlusJacobian(const double* quaternion) {
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> jacobian;
  ceres::EigenQuaternionManifold().PlusJacobian(quaternion, jacobian.data());
  return jacobian;
}

// Writes tangent rows (3 columns of block b) as Ceres' ambient Jacobian of block b: quaternion
// blocks through P^T (P = the manifold's PlusJacobian, P^T P = I), translations as they are.
template <typename Rows>
void WriteAmbient(const Rows& tangent, int block, const double* quaternion, double* jacobian) {
  const int rows = static_cast<int>(tangent.rows());
  if (kAmbientSizes[block] == 3) {
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(jacobian, rows, 3) =
        tangent.middleCols(3 * block, 3);
    return;
  }
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>>(jacobian, rows, 4) =
      tangent.middleCols(3 * block, 3) * PlusJacobian(quaternion).transpose();
}

}  // namespace

LidarPairPointToPlaneCost::LidarPairPointToPlaneCost(
    std::vector<PointToPlaneObservation> observations, double sigma, bool compress)
    : observations_(std::move(observations)),
      inverse_sigma_(1.0 / sigma),
      compressed_(compress && observations_.size() > kCompressedResiduals) {
  THROW_CHECK(!observations_.empty());
  THROW_CHECK_GT(sigma, 0);
  set_num_residuals(compressed_ ? kCompressedResiduals : static_cast<int>(observations_.size()));
  *mutable_parameter_block_sizes() = {4, 3, 4, 3, 4, 3};
}

ceres::CostFunction* LidarPairPointToPlaneCost::Create(
    std::vector<PointToPlaneObservation> observations, double sigma, bool compress) {
  return new LidarPairPointToPlaneCost(std::move(observations), sigma, compress);
}

// Per residual (camera i's frame, sigma omitted): a = R_e p + t_e, u = a - t_j, b = R_i R_j^T u + t_i,
// m = R_e n, g = R_j R_i^T m, r = m^T (b - R_e q - t_e). For left-multiplied rotation vectors w:
//   dr/dw_i = (b - t_i) x m,  dr/dt_i = m;   dr/dw_j = g x u,  dr/dt_j = -g;
//   dr/dw_e = m x (b - t_e) + (R_e p) x g,   dr/dt_e = g - m.
// The manifold's tangent rotates by twice its norm: d/d(tangent) = 2 d/dw.
void LidarPairPointToPlaneCost::Linearize(double const* const* parameters,
                                          Eigen::VectorXd* residuals,
                                          TangentJacobian* jacobian) const {
  const Eigen::Map<const Eigen::Quaterniond> rotation_i(parameters[0]);
  const Eigen::Map<const Eigen::Vector3d> translation_i(parameters[1]);
  const Eigen::Map<const Eigen::Quaterniond> rotation_j(parameters[2]);
  const Eigen::Map<const Eigen::Vector3d> translation_j(parameters[3]);
  const Eigen::Map<const Eigen::Quaterniond> rotation_e(parameters[4]);
  const Eigen::Map<const Eigen::Vector3d> translation_e(parameters[5]);
  const Eigen::Matrix3d r_e = rotation_e.toRotationMatrix();
  const Eigen::Matrix3d cam_i_from_cam_j =
      rotation_i.toRotationMatrix() * rotation_j.toRotationMatrix().transpose();
  const int n = static_cast<int>(observations_.size());
  residuals->resize(n);
  if (jacobian) jacobian->resize(n, kTangentSize);
  for (int k = 0; k < n; ++k) {
    const PointToPlaneObservation& observation = observations_[k];
    const Eigen::Vector3d rotated_p = r_e * observation.point_in_source;
    const Eigen::Vector3d u = rotated_p + translation_e - translation_j;
    const Eigen::Vector3d b = cam_i_from_cam_j * u + translation_i;
    const Eigen::Vector3d m = r_e * observation.normal_in_target * inverse_sigma_;
    (*residuals)[k] = m.dot(b - r_e * observation.point_in_target - translation_e);
    if (!jacobian) continue;
    const Eigen::Vector3d g = cam_i_from_cam_j.transpose() * m;
    auto row = jacobian->row(k);
    row.segment<3>(0) = 2 * (b - translation_i).cross(m);
    row.segment<3>(3) = m;
    row.segment<3>(6) = 2 * g.cross(u);
    row.segment<3>(9) = -g;
    row.segment<3>(12) = 2 * (m.cross(b - translation_e) + rotated_p.cross(g));
    row.segment<3>(15) = g - m;
  }
}

// Compressed form: with J^T J = V L V^T, the rows R = L^(1/2) V^T and residuals r' = L^(-1/2) V^T J^T r
// (zero where L is), plus e = sqrt(|r|^2 - |r'|^2) with a zero row. Then R^T R = J^T J, R^T r' = J^T r and
// |r'|^2 + e^2 = |r|^2: the same cost, gradient and Gauss-Newton model, in 19 rows instead of N.
bool LidarPairPointToPlaneCost::Evaluate(double const* const* parameters,
                                         double* residuals,
                                         double** jacobians) const {
  Eigen::VectorXd r;
  TangentJacobian j;
  Linearize(parameters, &r, jacobians ? &j : nullptr);
  if (!compressed_) {
    Eigen::Map<Eigen::VectorXd>(residuals, r.size()) = r;
    for (int block = 0; jacobians && block < 6; ++block) {
      if (jacobians[block]) WriteAmbient(j, block, parameters[block], jacobians[block]);
    }
    return true;
  }
  Eigen::Map<Eigen::VectorXd> out(residuals, kCompressedResiduals);
  out.setZero();
  if (!jacobians) {  // cost only
    out[kCompressedResiduals - 1] = r.norm();
    return true;
  }
  Eigen::Matrix<double, kTangentSize, kTangentSize> normal =
      Eigen::Matrix<double, kTangentSize, kTangentSize>::Zero();
  normal.selfadjointView<Eigen::Lower>().rankUpdate(j.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kTangentSize, kTangentSize>> eigen(
      normal.selfadjointView<Eigen::Lower>());
  const Eigen::Matrix<double, kTangentSize, 1> gradient = j.transpose() * r;
  TangentJacobian rows = TangentJacobian::Zero(kCompressedResiduals, kTangentSize);
  const double tolerance = 1e-12 * std::max(eigen.eigenvalues().maxCoeff(), 1e-300);
  for (int i = 0; i < kTangentSize; ++i) {
    const double lambda = eigen.eigenvalues()[i];
    if (lambda <= tolerance) continue;
    rows.row(i) = std::sqrt(lambda) * eigen.eigenvectors().col(i).transpose();
    out[i] = eigen.eigenvectors().col(i).dot(gradient) / std::sqrt(lambda);
  }
  out[kCompressedResiduals - 1] =
      std::sqrt(std::max(0.0, r.squaredNorm() - out.head<kTangentSize>().squaredNorm()));
  for (int block = 0; block < 6; ++block) {
    if (jacobians[block]) WriteAmbient(rows, block, parameters[block], jacobians[block]);
  }
  return true;
}

}  // namespace colmap_lidar
