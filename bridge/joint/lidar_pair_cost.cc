#include "bridge/joint/lidar_pair_cost.h"

#include "colmap_ext/logging.h"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <ceres/jet.h>
#include <ceres/manifold.h>

namespace colmap_lidar {
namespace {

constexpr int kTangentSize = 18;  // 3 per parameter block
constexpr int kAmbientSizes[6] = {4, 3, 4, 3, 4, 3};

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

using Jet = ceres::Jet<double, kTangentSize>;
using Matrix3J = Eigen::Matrix<Jet, 3, 3>;
using Vector3J = Eigen::Matrix<Jet, 3, 1>;

// The rotation of quaternion block `block` with the manifold's tangent as dual part: to first order
// (I + 2 [delta]x) R, since the tangent delta rotates by 2|delta|.
Matrix3J PerturbedRotation(const double* quaternion, int block) {
  Vector3J w;
  for (int i = 0; i < 3; ++i) w[i] = 2.0 * Jet(0.0, 3 * block + i);
  Matrix3J left;
  left << Jet(1.0), -w[2], w[1], w[2], Jet(1.0), -w[0], -w[1], w[0], Jet(1.0);
  const Eigen::Matrix3d rotation =
      Eigen::Map<const Eigen::Quaterniond>(quaternion).toRotationMatrix();
  return left * rotation.cast<Jet>();
}

Vector3J PerturbedTranslation(const double* translation, int block) {
  Vector3J t;
  for (int i = 0; i < 3; ++i) t[i] = Jet(translation[i], 3 * block + i);
  return t;
}

}  // namespace

LidarPairPointToPlaneCost::LidarPairPointToPlaneCost(
    std::vector<PointToPlaneObservation> observations,
    double sigma,
    bool compress,
    const colmap::Rigid3d& reference)
    : observations_(std::move(observations)),
      inverse_sigma_(1.0 / sigma),
      compressed_(compress && observations_.size() > kCompressedResiduals) {
  THROW_CHECK(!observations_.empty());
  THROW_CHECK_GT(sigma, 0);
  set_num_residuals(compressed_ ? kCompressedResiduals : static_cast<int>(observations_.size()));
  *mutable_parameter_block_sizes() = {4, 3, 4, 3, 4, 3};
  if (compressed_) BuildMoments(reference);
}

// The rows a_k = [vec(n p'^T), n, n^T (p~ - q)] / sigma (see the header) and S with S^T S = M.
void LidarPairPointToPlaneCost::BuildMoments(const colmap::Rigid3d& reference) {
  reference_rotation_transposed_ = reference.rotation.toRotationMatrix().transpose();
  std::vector<Eigen::Vector3d> moved;  // p~_k = T0 p_k
  moved.reserve(observations_.size());
  reference_centroid_.setZero();
  for (const PointToPlaneObservation& o : observations_) {
    moved.push_back(reference * o.point_in_source);
    reference_centroid_ += moved.back();
  }
  reference_centroid_ /= static_cast<double>(observations_.size());
  source_centroid_ = colmap::Inverse(reference) * reference_centroid_;
  Eigen::Matrix<double, Eigen::Dynamic, kCompressedResiduals> rows(observations_.size(),
                                                                   kCompressedResiduals);
  for (size_t k = 0; k < observations_.size(); ++k) {
    const Eigen::Vector3d& n = observations_[k].normal_in_target;
    const Eigen::Vector3d p = moved[k] - reference_centroid_;
    auto a = rows.row(k);
    for (int row = 0; row < 3; ++row) a.segment<3>(3 * row) = n[row] * p.transpose();
    a.segment<3>(9) = n.transpose();
    a[12] = n.dot(moved[k] - observations_[k].point_in_target);
  }
  // S from a QR decomposition of the rows (not from M = A^T A): backward stable, so the cost near T0
  // keeps the precision of the residuals themselves.
  const Eigen::HouseholderQR<Eigen::Matrix<double, Eigen::Dynamic, kCompressedResiduals>> qr(
      rows * inverse_sigma_);
  square_root_ = qr.matrixQR().topRows<kCompressedResiduals>().triangularView<Eigen::Upper>();
}

ceres::CostFunction* LidarPairPointToPlaneCost::Create(
    std::vector<PointToPlaneObservation> observations,
    double sigma,
    bool compress,
    const colmap::Rigid3d& reference) {
  return new LidarPairPointToPlaneCost(std::move(observations), sigma, compress, reference);
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

bool LidarPairPointToPlaneCost::Evaluate(double const* const* parameters,
                                         double* residuals,
                                         double** jacobians) const {
  if (compressed_) return EvaluateCompressed(parameters, residuals, jacobians);
  Eigen::VectorXd r;
  TangentJacobian j;
  Linearize(parameters, &r, jacobians ? &j : nullptr);
  Eigen::Map<Eigen::VectorXd>(residuals, r.size()) = r;
  for (int block = 0; jacobians && block < 6; ++block) {
    if (jacobians[block]) WriteAmbient(j, block, parameters[block], jacobians[block]);
  }
  return true;
}

// Compressed form (see the header): residuals S x(theta), Jacobian S dx/dtheta, with x and its tangent
// derivative from dual numbers (exact first order at the evaluation point).
bool LidarPairPointToPlaneCost::EvaluateCompressed(double const* const* parameters,
                                                   double* residuals,
                                                   double** jacobians) const {
  const Matrix3J rotation_i = PerturbedRotation(parameters[0], 0);
  const Vector3J translation_i = PerturbedTranslation(parameters[1], 1);
  const Matrix3J rotation_j = PerturbedRotation(parameters[2], 2);
  const Vector3J translation_j = PerturbedTranslation(parameters[3], 3);
  const Matrix3J rotation_e = PerturbedRotation(parameters[4], 4);
  const Vector3J translation_e = PerturbedTranslation(parameters[5], 5);
  // lidar_i_from_lidar_j = inverse(T_e) * cam_i_from_world * inverse(cam_j_from_world) * T_e.
  const Matrix3J cam_i_from_cam_j = rotation_i * rotation_j.transpose();
  const Matrix3J rotation = rotation_e.transpose() * cam_i_from_cam_j * rotation_e;
  const Vector3J translation =
      rotation_e.transpose() *
      (cam_i_from_cam_j * (translation_e - translation_j) + translation_i - translation_e);
  const Matrix3J change = rotation * reference_rotation_transposed_.cast<Jet>();  // R R0^T
  const Vector3J offset =
      rotation * source_centroid_.cast<Jet>() + translation - reference_centroid_.cast<Jet>();
  Eigen::Matrix<double, kCompressedResiduals, 1> x;
  // Fixed size: no allocation on the solver's hot path.
  using MomentJacobian = Eigen::Matrix<double, kCompressedResiduals, kTangentSize, Eigen::RowMajor>;
  MomentJacobian dx = MomentJacobian::Zero();
  for (int k = 0; k < 12; ++k) {
    const Jet& entry = k < 9 ? change(k / 3, k % 3) : offset[k - 9];
    x[k] = entry.a - (k < 9 && k % 4 == 0 ? 1.0 : 0.0);  // R R0^T - I
    dx.row(k) = entry.v.transpose();
  }
  x[12] = 1;
  Eigen::Map<Eigen::Matrix<double, kCompressedResiduals, 1>> out(residuals);
  out = square_root_ * x;
  if (!jacobians) return true;
  const MomentJacobian rows = square_root_ * dx;
  for (int block = 0; block < 6; ++block) {
    if (jacobians[block]) WriteAmbient(rows, block, parameters[block], jacobians[block]);
  }
  return true;
}

}  // namespace colmap_lidar
