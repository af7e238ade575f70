#include "bridge/joint/start_departure.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace colmap_lidar {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
// Without a sigma of the start: what a start without one is allowed to be off by.
constexpr double kAllowedRotationDeg = 2.0;
constexpr double kAllowedTranslationMm = 100.0;
constexpr double kAllowedSigmas = 3.0;
constexpr const char* kAxisNames[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};

// "round R of N moved it most (x deg, y mm); sigma / nominal sigma: reprojection ...".
std::string Evidence(const JointAdjustmentSummary& summary) {
  std::ostringstream text;
  text.precision(2);
  const auto& rounds = summary.extrinsic_change_per_round;
  const auto largest =
      std::max_element(rounds.begin(), rounds.end(), [](const auto& a, const auto& b) {
        return a[0] / kAllowedRotationDeg + a[1] / kAllowedTranslationMm <
               b[0] / kAllowedRotationDeg + b[1] / kAllowedTranslationMm;
      });
  if (largest != rounds.end()) {
    text << "round " << (largest - rounds.begin()) + 1 << " of " << rounds.size()
         << " moved it most (" << (*largest)[0] << " deg, " << (*largest)[1] << " mm)";
  }
  const VarianceFactors& factors = summary.variance_factors;
  text << "; sigma / nominal sigma: reprojection " << std::sqrt(factors.reprojection)
       << ", depth priors " << std::sqrt(factors.depth) << ", LiDAR " << std::sqrt(factors.lidar)
       << ", landmark-LiDAR " << std::sqrt(factors.landmark_lidar);
  return text.str();
}

// The prior's sigma per axis [deg, mm], if `data` has a prior.
std::optional<std::array<double, 6>> PriorSigma(const JointProblemData& data) {
  for (const ExtrinsicMeasurement& measurement : data.extrinsic_measurements) {
    if (!measurement.prior) continue;
    std::array<double, 6> sigma{};
    for (int k = 0; k < 6; ++k) {
      sigma[k] = std::sqrt(measurement.covariance(k, k)) * (k < 3 ? kRadToDeg : 1000.0);
    }
    return sigma;
  }
  return std::nullopt;
}

}  // namespace

std::array<double, 6> ExtrinsicAxisMove(const colmap::Rigid3d& from, const colmap::Rigid3d& to) {
  const Eigen::AngleAxisd rotation(to.rotation * from.rotation.inverse());
  const Eigen::Vector3d rotation_deg = kRadToDeg * rotation.angle() * rotation.axis();
  const Eigen::Vector3d translation_mm = 1000 * (to.translation - from.translation);
  return {rotation_deg(0),
          rotation_deg(1),
          rotation_deg(2),
          translation_mm(0),
          translation_mm(1),
          translation_mm(2)};
}

StartDeparture CheckStartDeparture(const colmap::Rigid3d& start,
                                   const colmap::Rigid3d& result,
                                   const JointProblemData& data,
                                   const JointAdjustmentSummary& summary) {
  const std::optional<std::array<double, 6>> start_sigma = PriorSigma(data);
  StartDeparture departure;
  departure.move = ExtrinsicAxisMove(start, result);
  const std::string evidence = Evidence(summary);
  for (int k = 0; k < 6; ++k) {
    departure.allowed[k] = start_sigma ? kAllowedSigmas * (*start_sigma)[k]
                                       : (k < 3 ? kAllowedRotationDeg : kAllowedTranslationMm);
    departure.beyond[k] =
        !summary.uncertainty.undetermined[k] && std::abs(departure.move[k]) > departure.allowed[k];
    if (!departure.beyond[k]) continue;
    std::ostringstream line;
    line.precision(3);
    line << kAxisNames[k] << " moved " << departure.move[k] << (k < 3 ? " deg" : " mm")
         << " from the start, beyond the " << departure.allowed[k] << (k < 3 ? " deg" : " mm")
         << (start_sigma ? " of 3 sigmas of the prior" : " a start without a sigma is allowed")
         << "; " << evidence;
    departure.warnings.push_back(line.str());
  }
  return departure;
}

}  // namespace colmap_lidar
