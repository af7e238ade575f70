#include "bridge/initialization/vertical_alignment.h"

#include "colmap_ext/logging.h"
#include "lidar/util/parallel_for_each.h"

#include "colmap/geometry/pose.h"
#include "colmap/geometry/rigid3.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace colmap_lidar {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr int kNumLinearisations = 3;

PerpendicularDirection LidarVertical(const VerticalStationInput& station,
                                     const Eigen::Vector3d& guess,
                                     const VerticalAlignmentOptions& options) {
  const PointCloud& cloud = *station.cloud;
  std::vector<Eigen::Vector3d> planar_normals;
  planar_normals.reserve(cloud.Size());
  for (size_t i = 0; i < cloud.Size(); ++i) {
    const bool has_normal = cloud.normals[i].squaredNorm() > 0.5;
    if (has_normal && (*station.curvature)[i] <= options.max_curvature) {
      planar_normals.push_back(cloud.normals[i]);  // the fit's gate keeps the walls
    }
  }
  return FitPerpendicularDirection(planar_normals, {}, guess, options.lidar_fit);
}

PerpendicularDirection CameraVertical(const VerticalStationInput& station,
                                      const Eigen::Vector3d& guess,
                                      const VerticalAlignmentOptions& options,
                                      size_t* num_segments) {
  const std::vector<LineSegment> segments =
      DetectLineSegments(station.image_path, options.segments);
  std::vector<Eigen::Vector3d> plane_normals;
  std::vector<double> weights;
  for (const LineSegment& segment : segments) {
    plane_normals.push_back(InterpretationPlaneNormal(*station.camera, segment));
    // The plane's tilt error falls with the segment's length (end-point noise / length).
    weights.push_back(std::pow(segment.Length() / 100.0, 2));
  }
  *num_segments = segments.size();
  return FitPerpendicularDirection(plane_normals, weights, guess, options.camera_fit);
}

// Station i's linear model: r_i = b_i + A_i alpha with r_i ~ N(0, C_i + s^2 I), in the tangent of
// its camera vertical d_i; v_i = R up_in_lidar_i, exp(axes alpha) v_i ~ v_i - [v_i]x axes alpha.
struct StationEquation {
  Eigen::Vector2d offset;      // b_i
  Eigen::Matrix2d jacobian;    // A_i
  Eigen::Matrix2d covariance;  // C_i
};

StationEquation Linearise(const StationVertical& station,
                          const Eigen::Matrix3d& cam_from_lidar,
                          const Eigen::Matrix<double, 3, 2>& axes) {
  const Eigen::Vector3d up_lidar_in_cam = cam_from_lidar * station.up_in_lidar.direction;
  const Eigen::Matrix<double, 3, 2>& tangent = station.up_in_cam.tangent;
  StationEquation equation;
  equation.offset = tangent.transpose() * (up_lidar_in_cam - station.up_in_cam.direction);
  equation.jacobian = -tangent.transpose() * colmap::CrossProductMatrix(up_lidar_in_cam) * axes;
  const Eigen::Matrix2d lidar_to_cam_tangent =
      tangent.transpose() * cam_from_lidar * station.up_in_lidar.tangent;
  equation.covariance =
      lidar_to_cam_tangent * station.up_in_lidar.covariance * lidar_to_cam_tangent.transpose() +
      station.up_in_cam.covariance;
  return equation;
}

// (C_i + s^2 I)^-1
Eigen::Matrix2d StationWeight(const StationEquation& e, double station_variance) {
  return (e.covariance + station_variance * Eigen::Matrix2d::Identity()).inverse();
}

double StationChi2(const StationEquation& e,
                   const Eigen::Vector2d& alpha,
                   double station_variance) {
  const Eigen::Vector2d r = e.offset + e.jacobian * alpha;
  return r.dot(StationWeight(e, station_variance) * r);
}

struct WeightedFit {
  Eigen::Vector2d alpha = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  double chi2 = 0;
  size_t num_used = 0;
};

WeightedFit SolveWeighted(const std::vector<StationEquation>& equations,
                          const std::vector<bool>& used,
                          double station_variance) {
  Eigen::Matrix2d information = Eigen::Matrix2d::Zero();
  Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
  WeightedFit fit;
  for (size_t i = 0; i < equations.size(); ++i) {
    if (!used[i]) continue;
    const StationEquation& e = equations[i];
    const Eigen::Matrix2d weight = StationWeight(e, station_variance);
    information += e.jacobian.transpose() * weight * e.jacobian;
    gradient += e.jacobian.transpose() * weight * e.offset;
    ++fit.num_used;
  }
  fit.covariance = information.inverse();
  fit.alpha = -fit.covariance * gradient;
  for (size_t i = 0; i < equations.size(); ++i) {
    if (used[i]) fit.chi2 += StationChi2(equations[i], fit.alpha, station_variance);
  }
  return fit;
}

// The structure variance s^2 that brings chi2 to its degrees of freedom (0 if already below), by
// bisection in log s^2 between (0.0006 deg)^2 and (6 deg)^2.
double StationVariance(const std::vector<StationEquation>& equations,
                       const std::vector<bool>& used) {
  const WeightedFit plain = SolveWeighted(equations, used, 0.0);
  const double dof = 2.0 * plain.num_used - 2.0;
  if (plain.chi2 <= dof) return 0.0;
  double low = std::log(1e-10), high = std::log(1e-2);
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (low + high);
    (SolveWeighted(equations, used, std::exp(mid)).chi2 > dof ? low : high) = mid;
  }
  return std::exp(high);
}

// Lag-1 autocorrelation of the used stations' residuals (in their order), the larger over the two
// axes, clamped to [0, 0.99].
double SerialCorrelation(const std::vector<StationVertical>& stations) {
  std::vector<Eigen::Vector2d> residuals;
  for (const StationVertical& station : stations) {
    if (station.used) residuals.push_back(station.residual_deg);
  }
  if (residuals.size() < 3) return 0.0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& r : residuals) mean += r / residuals.size();
  Eigen::Vector2d lagged = Eigen::Vector2d::Zero(), squared = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < residuals.size(); ++k) {
    squared += (residuals[k] - mean).cwiseAbs2();
    if (k + 1 < residuals.size()) {
      lagged += (residuals[k] - mean).cwiseProduct(residuals[k + 1] - mean);
    }
  }
  double rho = 0;
  for (int axis = 0; axis < 2; ++axis) {
    if (squared(axis) > 0) rho = std::max(rho, lagged(axis) / squared(axis));
  }
  return std::min(rho, 0.99);
}

// Inflates the covariance for serially correlated stations (VerticalAlignment::serial_correlation).
void InflateForSerialCorrelation(size_t num_used, VerticalAlignment* result) {
  result->serial_correlation = SerialCorrelation(result->stations);
  const double rho = result->serial_correlation;
  const double inflation =
      std::min(static_cast<double>(std::max<size_t>(num_used, 1)), (1 + rho) / (1 - rho));
  result->covariance *= inflation;
  result->effective_stations = num_used / inflation;
}

void MeasureStations(const std::vector<VerticalStationInput>& inputs,
                     const Eigen::Matrix3d& cam_from_lidar,
                     const Eigen::Vector3d& up_in_lidar_guess,
                     const VerticalAlignmentOptions& options,
                     std::vector<StationVertical>* stations) {
  stations->resize(inputs.size());
  // An unreadable image throws; ParallelForEach carries it out of the OpenMP region.
  ParallelForEach(static_cast<int>(inputs.size()), [&](int i) {
    StationVertical& station = (*stations)[i];
    station.name = inputs[i].name;
    station.up_in_lidar = LidarVertical(inputs[i], up_in_lidar_guess, options);
    if (!station.up_in_lidar.valid) return;
    station.up_in_cam = CameraVertical(
        inputs[i], cam_from_lidar * station.up_in_lidar.direction, options, &station.num_segments);
  });
}

// Random-effects fit, stations beyond max_station_chi2 left out once, fit again; fills the result.
void FitAndReject(const std::vector<StationEquation>& equations,
                  const VerticalAlignmentOptions& options,
                  std::vector<bool>* used,
                  VerticalAlignment* result) {
  double variance = StationVariance(equations, *used);
  const WeightedFit first = SolveWeighted(equations, *used, variance);
  for (size_t i = 0; i < equations.size(); ++i) {
    if ((*used)[i] && StationChi2(equations[i], first.alpha, variance) > options.max_station_chi2) {
      (*used)[i] = false;
    }
  }
  variance = StationVariance(equations, *used);
  const WeightedFit fit = SolveWeighted(equations, *used, variance);
  result->correction = fit.alpha;
  result->covariance = fit.covariance;
  result->station_variance = variance;
  for (size_t i = 0; i < equations.size(); ++i) {
    StationVertical& station = result->stations[i];
    station.used = (*used)[i];
    if (station.up_in_cam.valid) {
      const Eigen::Vector2d residual = equations[i].offset + equations[i].jacobian * fit.alpha;
      station.residual_deg =
          kRadToDeg * result->axes.transpose() * station.up_in_cam.tangent * residual;
    }
  }
  InflateForSerialCorrelation(fit.num_used, result);
  std::ostringstream message;
  message << fit.num_used << " of " << equations.size() << " stations, structure scatter "
          << kRadToDeg * std::sqrt(variance) << " deg per station, serial correlation "
          << result->serial_correlation << " (" << result->effective_stations
          << " independent stations)";
  result->message = message.str();
  result->valid = fit.num_used >= options.min_num_stations;
}

}  // namespace

bool VerticalAlignmentOptions::Check() const {
  CHECK_OPTION(lidar_fit.Check());
  CHECK_OPTION(camera_fit.Check());
  CHECK_OPTION(segments.Check());
  CHECK_OPTION_GT(max_curvature, 0);
  CHECK_OPTION_GT(max_station_chi2, 0);
  CHECK_OPTION_GE(min_num_stations, 2);
  return true;
}

bool VerticalAlignment::Significant() const {
  constexpr double kChi2TwoDof95 = 5.991;
  return valid && correction.dot(covariance.ldlt().solve(correction)) > kChi2TwoDof95;
}

Eigen::Quaterniond VerticalAlignment::Corrected(
    const Eigen::Quaterniond& cam_from_lidar_rotation) const {
  const Eigen::Vector3d omega = axes * correction;
  const double angle = omega.norm();
  if (angle == 0) return cam_from_lidar_rotation;
  return (Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle)) * cam_from_lidar_rotation)
      .normalized();
}

Eigen::Matrix3d VerticalAlignment::RotationCovariance(double unmeasured_variance) const {
  const Eigen::Vector3d vertical = axes.col(0).cross(axes.col(1));
  return axes * covariance * axes.transpose() +
         unmeasured_variance * vertical * vertical.transpose();
}

VerticalAlignment MeasureVerticalAlignment(const std::vector<VerticalStationInput>& inputs,
                                           const Eigen::Quaterniond& cam_from_lidar_rotation,
                                           const Eigen::Vector3d& up_in_lidar_guess,
                                           const VerticalAlignmentOptions& options) {
  THROW_CHECK(options.Check());
  for (const VerticalStationInput& input : inputs) {
    THROW_CHECK(input.camera && input.cloud && input.curvature) << "station " << input.name;
    THROW_CHECK_EQ(input.cloud->normals.size(), input.cloud->Size())
        << "station " << input.name << ": the cloud needs normals";
    THROW_CHECK_EQ(input.curvature->size(), input.cloud->Size())
        << "station " << input.name << ": one curvature per point";
  }
  const Eigen::Matrix3d cam_from_lidar = cam_from_lidar_rotation.toRotationMatrix();
  VerticalAlignment result;
  MeasureStations(inputs, cam_from_lidar, up_in_lidar_guess, options, &result.stations);
  std::vector<bool> used(inputs.size());
  Eigen::Vector3d mean_vertical = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < inputs.size(); ++i) {
    used[i] = result.stations[i].up_in_lidar.valid && result.stations[i].up_in_cam.valid;
    if (used[i]) mean_vertical += result.stations[i].up_in_cam.direction;
  }
  if (std::count(used.begin(), used.end(), true) < long(options.min_num_stations)) {
    result.message = "too few stations with a vertical in both the cloud and the image";
    return result;
  }
  result.axes = TangentBasis(mean_vertical.normalized());
  // Gauss-Newton: linearised again at the corrected rotation (a drive's start can be degrees off,
  // beyond what one linear step corrects).
  Eigen::Vector2d correction = Eigen::Vector2d::Zero();
  for (int k = 0; k < kNumLinearisations; ++k) {
    result.correction = correction;
    const Eigen::Matrix3d rotation = result.Corrected(cam_from_lidar_rotation).toRotationMatrix();
    std::vector<StationEquation> equations;
    for (const StationVertical& station : result.stations) {
      equations.push_back(station.up_in_cam.valid ? Linearise(station, rotation, result.axes)
                                                  : StationEquation{});
    }
    std::vector<bool> used_now = used;
    FitAndReject(equations, options, &used_now, &result);
    correction += result.correction;
  }
  result.correction = correction;
  return result;
}

}  // namespace colmap_lidar
