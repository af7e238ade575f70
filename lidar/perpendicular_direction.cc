#include "lidar/perpendicular_direction.h"

#include "lidar/util/check_option.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
// an eigenvalue of the normal matrix below this fraction of the largest carries no information
constexpr double kMinRelativeInformation = 1e-2;
// the gate never cuts the residuals' distribution closer than this many robust sigmas
constexpr double kGateSigmas = 3.0;

struct NormalEquations {
  Eigen::Matrix2d information = Eigen::Matrix2d::Zero();
  Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
  double weighted_square_sum = 0;
  double weight_sum = 0;
  size_t num_inliers = 0;
  // 1.4826 median |r| of the inliers: the gate's scale, which outliers within the gate do not inflate
  double robust_sigma = 0;
};

// Residual r_i = v_i . d of the inliers within `max_angle_rad` of perpendicular, linearised in the
// tilt: dr/d(a, b) = v_i^T [t1 t2].
NormalEquations Accumulate(const std::vector<Eigen::Vector3d>& vectors,
                           const std::vector<double>& weights,
                           const Eigen::Vector3d& direction,
                           const Eigen::Matrix<double, 3, 2>& tangent,
                           double max_angle_rad) {
  NormalEquations equations;
  std::vector<double> abs_residuals;
  const double max_residual = std::sin(max_angle_rad);
  for (size_t i = 0; i < vectors.size(); ++i) {
    const double residual = vectors[i].dot(direction);
    if (!std::isfinite(residual) || std::abs(residual) > max_residual) continue;
    const double weight = weights.empty() ? 1.0 : weights[i];
    const Eigen::Vector2d jacobian = tangent.transpose() * vectors[i];
    equations.information += weight * jacobian * jacobian.transpose();
    equations.gradient += weight * jacobian * residual;
    equations.weighted_square_sum += weight * residual * residual;
    equations.weight_sum += weight;
    ++equations.num_inliers;
    abs_residuals.push_back(std::abs(residual));
  }
  if (!abs_residuals.empty()) {
    auto middle = abs_residuals.begin() + abs_residuals.size() / 2;
    std::nth_element(abs_residuals.begin(), middle, abs_residuals.end());
    equations.robust_sigma = 1.4826 * *middle;
  }
  return equations;
}

struct GaussNewtonStep {
  bool valid = false;
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
};

// Step and covariance (residual variance / information) on the informed eigen-directions of the
// normal matrix; an uninformed one keeps the current tilt and gets kUnknownTiltVariance.
GaussNewtonStep Solve(const NormalEquations& equations) {
  GaussNewtonStep step;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(equations.information);
  const Eigen::Vector2d values = eigen.eigenvalues();
  if (!(values(1) > 0) || equations.num_inliers < 3) return step;
  const double residual_variance =
      equations.weighted_square_sum / (double(equations.num_inliers) - 2.0);
  for (int e = 0; e < 2; ++e) {
    const Eigen::Vector2d axis = eigen.eigenvectors().col(e);
    if (values(e) < kMinRelativeInformation * values(1)) {
      step.covariance += kUnknownTiltVariance * axis * axis.transpose();
      continue;
    }
    step.tilt -= axis * axis.dot(equations.gradient) / values(e);
    step.covariance += residual_variance / values(e) * axis * axis.transpose();
  }
  step.valid = true;
  return step;
}

// Gate of iteration k: geometric from the initial to the final angle.
double GateRad(const PerpendicularDirectionOptions& options, int k) {
  const double t = options.num_iterations > 1 ? double(k) / (options.num_iterations - 1) : 1.0;
  return kDegToRad * options.initial_max_angle_deg *
         std::pow(options.final_max_angle_deg / options.initial_max_angle_deg, t);
}

}  // namespace

bool PerpendicularDirectionOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(final_max_angle_deg, 0);
  LIDAR_CHECK_OPTION_GE(initial_max_angle_deg, final_max_angle_deg);
  LIDAR_CHECK_OPTION_LT(initial_max_angle_deg, 90);
  LIDAR_CHECK_OPTION_GE(num_iterations, 1);
  LIDAR_CHECK_OPTION_GE(min_num_inliers, 3);
  return true;
}

Eigen::Matrix<double, 3, 2> TangentBasis(const Eigen::Vector3d& direction) {
  const Eigen::Vector3d first = direction.unitOrthogonal();
  Eigen::Matrix<double, 3, 2> tangent;
  tangent << first, direction.cross(first);
  return tangent;
}

PerpendicularDirection FitPerpendicularDirection(const std::vector<Eigen::Vector3d>& unit_vectors,
                                                 const std::vector<double>& weights,
                                                 const Eigen::Vector3d& guess,
                                                 const PerpendicularDirectionOptions& options) {
  ThrowUnlessValid(options, "FitPerpendicularDirection");
  if (!weights.empty() && weights.size() != unit_vectors.size()) {
    throw std::invalid_argument("FitPerpendicularDirection: one weight per vector, or none");
  }
  PerpendicularDirection result;
  result.direction = guess.normalized();
  double robust_sigma = 0;
  // The last pass only measures: covariance and RMS in the final direction's own tangent.
  for (int k = 0; k <= options.num_iterations; ++k) {
    result.tangent = TangentBasis(result.direction);
    const double gate = std::max(GateRad(options, std::min(k, options.num_iterations - 1)),
                                 kGateSigmas * robust_sigma);
    const NormalEquations equations =
        Accumulate(unit_vectors, weights, result.direction, result.tangent, gate);
    const GaussNewtonStep step = Solve(equations);
    if (equations.num_inliers < options.min_num_inliers || !step.valid) {
      return PerpendicularDirection();
    }
    result.num_inliers = equations.num_inliers;
    robust_sigma = equations.robust_sigma;
    result.covariance = step.covariance;
    result.rms_deg = std::sqrt(equations.weighted_square_sum / equations.weight_sum) / kDegToRad;
    if (k < options.num_iterations) {
      result.direction = (result.direction + result.tangent * step.tilt).normalized();
    }
  }
  result.valid = true;
  return result;
}

}  // namespace colmap_lidar
