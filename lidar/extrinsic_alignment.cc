#include "lidar/extrinsic_alignment.h"

#include "lidar/point_to_plane_icp.h"
#include "lidar/util/check_option.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

struct WeightedNormalEquations {
  Matrix6d H = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  // sum w J dr/ds, s a relative scale of every depth (p_cam -> (1 + s) p_cam)
  Vector6d scale_gradient = Vector6d::Zero();
  double squared_m = 0;       // sum r^2 of the associations
  double squared_sigmas = 0;  // sum (r / sigma)^2
  double robust_squared = 0;  // sum w (r / sigma)^2
  double squared_lever = 0;   // sum |p'|^2: the lever arm of the rotations
  size_t count = 0;

  void Add(const WeightedNormalEquations& other) {
    H += other.H;
    g += other.g;
    scale_gradient += other.scale_gradient;
    squared_m += other.squared_m;
    squared_sigmas += other.squared_sigmas;
    robust_squared += other.robust_squared;
    squared_lever += other.squared_lever;
    count += other.count;
  }
};

// One station's contribution, linearised about lidar_from_cam with a left increment [omega, t] in
// the LiDAR frame: r = n^T (p' - q), d r / d[omega, t] = [p' x n, n] (as in PointToPlaneIcp).
WeightedNormalEquations StationEquations(const CameraDepthPoints& points,
                                         const StationCloud& station,
                                         const Eigen::Isometry3d& lidar_from_cam,
                                         double gate,
                                         const ExtrinsicAlignmentOptions& options) {
  WeightedNormalEquations eq;
  const Eigen::Vector3d camera_in_lidar = lidar_from_cam.translation();
  const double lidar_variance = options.sigma_lidar_m * options.sigma_lidar_m;
  for (size_t k = 0; k < points.point_in_cam.size(); ++k) {
    const Eigen::Vector3d p = lidar_from_cam * points.point_in_cam[k];
    size_t index = 0;
    double squared = 0;
    if (!station.tree->Nearest(p, &index, &squared) || squared > gate * gate ||
        station.curvature[index] > options.max_curvature) {
      continue;
    }
    const Eigen::Vector3d& n = station.cloud.normals[index];
    if (n.squaredNorm() < 0.5) continue;  // no normal estimated there
    const double r = n.dot(p - station.cloud.points[index]);
    // The depth error lies along the viewing ray; its share along the normal.
    const double along_normal =
        points.sigma_along_ray_m[k] * n.dot((p - camera_in_lidar).normalized());
    const double sigma = std::sqrt(lidar_variance + along_normal * along_normal);
    const double z = std::abs(r) / sigma;
    const double huber = z <= options.huber_sigmas ? 1.0 : options.huber_sigmas / z;
    const double w = huber / (sigma * sigma);
    Vector6d J;
    J << p.cross(n), n;
    eq.H.noalias() += w * J * J.transpose();
    eq.g.noalias() += w * J * r;
    eq.scale_gradient.noalias() += w * J * n.dot(p - camera_in_lidar);
    eq.squared_m += r * r;
    eq.squared_sigmas += z * z;
    eq.robust_squared += huber * z * z;
    eq.squared_lever += p.squaredNorm();
    ++eq.count;
  }
  return eq;
}

std::vector<WeightedNormalEquations> StationEquationsOfAll(
    const std::vector<CameraDepthPoints>& points,
    const std::vector<const StationCloud*>& clouds,
    const Eigen::Isometry3d& lidar_from_cam,
    double gate,
    const ExtrinsicAlignmentOptions& options) {
  std::vector<WeightedNormalEquations> per_station(points.size());
#pragma omp parallel for schedule(dynamic)
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    per_station[i] = StationEquations(points[i], *clouds[i], lidar_from_cam, gate, options);
  }
  return per_station;
}

WeightedNormalEquations Sum(const std::vector<WeightedNormalEquations>& per_station) {
  WeightedNormalEquations total;
  for (const WeightedNormalEquations& eq : per_station) total.Add(eq);
  return total;
}

int NumStationsWithAssociations(const std::vector<WeightedNormalEquations>& per_station) {
  return static_cast<int>(
      std::count_if(per_station.begin(), per_station.end(), [](const WeightedNormalEquations& eq) {
        return eq.count > 0;
      }));
}

// The weak prior's information and its pull towards the start, in the same increment coordinates.
Matrix6d PriorInformation(const ExtrinsicAlignmentOptions& options) {
  Vector6d diagonal;
  const double rotation = options.prior_rotation_deg * kDegToRad;
  diagonal << Eigen::Vector3d::Constant(1 / (rotation * rotation)),
      Eigen::Vector3d::Constant(1 / (options.prior_translation_m * options.prior_translation_m));
  return diagonal.asDiagonal();
}

Vector6d DeviationFromStart(const Eigen::Isometry3d& lidar_from_cam,
                            const Eigen::Isometry3d& start_lidar_from_cam) {
  const Eigen::Matrix3d rotation =
      lidar_from_cam.linear() * start_lidar_from_cam.linear().transpose();
  const Eigen::AngleAxisd angle_axis(rotation);
  Vector6d deviation;
  deviation << angle_axis.angle() * angle_axis.axis(),
      lidar_from_cam.translation() - rotation * start_lidar_from_cam.translation();
  return deviation;
}

// The data's directions in [omega * lever, t] (metres both), weakest first, and their information
// relative to the strongest: a direction below `min_ratio` is one the scenes do not constrain (noise
// in the LiDAR normals gives a plane's tangent directions a small ratio of their own; see the
// option)
struct DataDirections {
  Matrix6d scale = Matrix6d::Identity();  // x = scale * y
  Eigen::Matrix<double, 6, 6> vectors;    // columns, in y
  Vector6d eigenvalues;                   // of scale H scale, ascending
  Vector6d ratios;
  int num_weak = 0;
};

DataDirections AnalyseDirections(const WeightedNormalEquations& eq, double min_ratio) {
  DataDirections directions;
  const double lever = std::max(1.0, std::sqrt(eq.squared_lever / std::max<size_t>(eq.count, 1)));
  directions.scale.topLeftCorner<3, 3>() /= lever;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(directions.scale * eq.H * directions.scale);
  directions.vectors = solver.eigenvectors();
  directions.eigenvalues = solver.eigenvalues();
  directions.ratios = directions.eigenvalues / std::max(directions.eigenvalues(5), 1e-300);
  while (directions.num_weak < 6 && directions.ratios(directions.num_weak) < min_ratio) {
    ++directions.num_weak;
  }
  return directions;
}

// The step without its components along the weak directions (Zhang et al. 2016, "solution
// remapping"): what the data do not determine stays where it was.
Vector6d WithoutWeakDirections(const Vector6d& x, const DataDirections& directions) {
  if (directions.num_weak == 0) return x;
  const Matrix6d inverse_scale = directions.scale.inverse();
  Vector6d y = inverse_scale * x;
  for (int k = 0; k < directions.num_weak; ++k) {
    y -= directions.vectors.col(k) * directions.vectors.col(k).dot(y);
  }
  return directions.scale * y;
}

// (scale H scale)^+ over the directions the data determine, in y; and the prior's translation
// variance along the weak ones (unknown; held at the start).
Matrix6d DeterminedInverseY(const DataDirections& directions) {
  Matrix6d inverse_y = Matrix6d::Zero();
  for (int k = directions.num_weak; k < 6; ++k) {
    inverse_y += directions.vectors.col(k) * directions.vectors.col(k).transpose() /
                 directions.eigenvalues(k);
  }
  return inverse_y;
}

Matrix6d WeakCovarianceY(const DataDirections& directions,
                         const ExtrinsicAlignmentOptions& options) {
  Matrix6d weak_y = Matrix6d::Zero();
  for (int k = 0; k < directions.num_weak; ++k) {
    weak_y += directions.vectors.col(k) * directions.vectors.col(k).transpose();
  }
  return options.prior_translation_m * options.prior_translation_m * weak_y;
}

// Covariance of the increment [omega, t] in the LiDAR frame: the data's (scaled by the residual
// variance) along the directions they determine, the prior's along the weak ones.
Matrix6d Covariance(const DataDirections& directions,
                    double variance,
                    const ExtrinsicAlignmentOptions& options) {
  return directions.scale *
         (variance * DeterminedInverseY(directions) + WeakCovarianceY(directions, options)) *
         directions.scale;
}

// The same from the scatter of the stations' own scores g_s = sum w J r (cluster-robust, a sandwich
// H^-1 (G / (G - 1)) sum_s g_s g_s^T H^-1): errors shared within a station (a stereo bias over a
// surface, the cloud's normals) count once per station, not once per point.
Matrix6d StationClusteredCovariance(const std::vector<WeightedNormalEquations>& per_station,
                                    const DataDirections& directions,
                                    const ExtrinsicAlignmentOptions& options) {
  Matrix6d meat_y = Matrix6d::Zero();
  for (const WeightedNormalEquations& eq : per_station) {
    const Vector6d score_y = directions.scale * eq.g;  // zero for a station without associations
    meat_y += score_y * score_y.transpose();
  }
  const double num_stations = NumStationsWithAssociations(per_station);
  if (num_stations > 1) meat_y *= num_stations / (num_stations - 1);
  const Matrix6d inverse_y = DeterminedInverseY(directions);
  return directions.scale *
         (inverse_y * meat_y * inverse_y + WeakCovarianceY(directions, options)) * directions.scale;
}

// A depth scale error s common to every station (a stereo baseline or focal length off, a sub-pixel
// bias) moves the solution by dx/ds = -H^+ sum w J dr/ds; no scatter of residuals reveals it, so it
// enters as a consider parameter, sigma_s^2 (dx/ds)(dx/ds)^T.
Matrix6d DepthScaleCovariance(const WeightedNormalEquations& eq,
                              const DataDirections& directions,
                              const ExtrinsicAlignmentOptions& options) {
  const Vector6d response =
      -directions.scale * DeterminedInverseY(directions) * directions.scale * eq.scale_gradient;
  return options.depth_scale_sigma * options.depth_scale_sigma * response * response.transpose();
}

// cam_from_lidar's covariance about / along the camera's axes: lidar_from_cam <- exp(d)
// lidar_from_cam is cam_from_lidar <- cam_from_lidar exp(-d), a change R (-omega) of its rotation
// (left of it) and -R t of its translation in the camera frame, R = cam_from_lidar's rotation.
void SetCovariance(const Matrix6d& covariance_in_lidar,
                   const Eigen::Isometry3d& cam_from_lidar,
                   ExtrinsicAlignmentResult* result) {
  Matrix6d to_cam = Matrix6d::Zero();
  to_cam.topLeftCorner<3, 3>() = cam_from_lidar.linear();
  to_cam.bottomRightCorner<3, 3>() = cam_from_lidar.linear();
  result->covariance_in_cam = to_cam * covariance_in_lidar * to_cam.transpose();
  for (int axis = 0; axis < 3; ++axis) {
    result->sigma_rotation_deg[axis] = std::sqrt(result->covariance_in_cam(axis, axis)) / kDegToRad;
    result->sigma_translation_m[axis] = std::sqrt(result->covariance_in_cam(3 + axis, 3 + axis));
  }
}

}  // namespace

bool ExtrinsicAlignmentOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(min_correspondence_distance_m, 0);
  LIDAR_CHECK_OPTION_GE(max_correspondence_distance_m, min_correspondence_distance_m);
  LIDAR_CHECK_OPTION_GE(max_iterations, 1);
  LIDAR_CHECK_OPTION_GT(max_curvature, 0);
  LIDAR_CHECK_OPTION_GT(sigma_lidar_m, 0);
  LIDAR_CHECK_OPTION_GT(huber_sigmas, 0);
  LIDAR_CHECK_OPTION_GE(min_constraint_ratio, 0);
  LIDAR_CHECK_OPTION_LT(min_constraint_ratio, 1);
  LIDAR_CHECK_OPTION_GT(prior_rotation_deg, 0);
  LIDAR_CHECK_OPTION_GT(prior_translation_m, 0);
  LIDAR_CHECK_OPTION_GT(convergence_rotation_deg, 0);
  LIDAR_CHECK_OPTION_GT(convergence_translation_m, 0);
  LIDAR_CHECK_OPTION_GE(min_station_clusters, 2);
  LIDAR_CHECK_OPTION_GE(depth_scale_sigma, 0);
  return true;
}

ExtrinsicAlignmentResult AlignCameraPointsWithLidar(const std::vector<CameraDepthPoints>& points,
                                                    const std::vector<const StationCloud*>& clouds,
                                                    const Eigen::Isometry3d& initial_cam_from_lidar,
                                                    const ExtrinsicAlignmentOptions& options) {
  ThrowUnlessValid(options, "ExtrinsicAlignmentOptions");
  if (points.size() != clouds.size()) {
    throw std::invalid_argument("AlignCameraPointsWithLidar: " + std::to_string(points.size()) +
                                " point sets for " + std::to_string(clouds.size()) + " clouds");
  }
  ExtrinsicAlignmentResult result;
  for (size_t i = 0; i < points.size(); ++i) {
    if (points[i].point_in_cam.size() != points[i].sigma_along_ray_m.size() || !clouds[i] ||
        !clouds[i]->tree || clouds[i]->curvature.size() != clouds[i]->cloud.Size()) {
      throw std::invalid_argument("AlignCameraPointsWithLidar: station " + std::to_string(i) +
                                  " has mismatched points, sigmas or an unprepared cloud");
    }
    result.num_points += points[i].point_in_cam.size();
  }
  const Eigen::Isometry3d start = initial_cam_from_lidar.inverse();
  const Matrix6d prior = PriorInformation(options);
  Eigen::Isometry3d lidar_from_cam = start;
  double gate = options.max_correspondence_distance_m;
  WeightedNormalEquations eq;
  for (int it = 0; it < options.max_iterations; ++it) {
    eq = Sum(StationEquationsOfAll(points, clouds, lidar_from_cam, gate, options));
    result.iterations = it + 1;
    if (eq.count < 6) break;
    const DataDirections directions = AnalyseDirections(eq, options.min_constraint_ratio);
    const Vector6d x = WithoutWeakDirections(
        (eq.H + prior).ldlt().solve(-(eq.g + prior * DeviationFromStart(lidar_from_cam, start))),
        directions);
    if (!x.allFinite()) break;
    lidar_from_cam = IsometryFromIncrement(x) * lidar_from_cam;
    const bool small_step = x.head<3>().norm() < options.convergence_rotation_deg * kDegToRad &&
                            x.tail<3>().norm() < options.convergence_translation_m;
    const double next_gate = NextIcpGate(
        gate, std::sqrt(eq.squared_m / eq.count), options.min_correspondence_distance_m);
    if (small_step && next_gate > 0.98 * gate) {
      result.converged = true;
      break;
    }
    gate = next_gate;
  }
  const std::vector<WeightedNormalEquations> per_station =
      StationEquationsOfAll(points, clouds, lidar_from_cam, gate, options);
  eq = Sum(per_station);
  result.cam_from_lidar = lidar_from_cam.inverse();
  result.num_associations = eq.count;
  if (eq.count < 6) return result;
  result.rms_m = std::sqrt(eq.squared_m / eq.count);
  result.rms_sigmas = std::sqrt(eq.squared_sigmas / eq.count);
  const DataDirections directions = AnalyseDirections(eq, options.min_constraint_ratio);
  result.constraint_ratios = directions.ratios;
  result.num_weak_directions = directions.num_weak;
  const double variance = std::max(1.0, eq.robust_squared / std::max<double>(eq.count - 6, 1));
  result.num_station_clusters = NumStationsWithAssociations(per_station);
  result.station_clustered = result.num_station_clusters >= options.min_station_clusters;
  Matrix6d covariance = result.station_clustered
                            ? StationClusteredCovariance(per_station, directions, options)
                            : Covariance(directions, variance, options);
  covariance += DepthScaleCovariance(eq, directions, options);
  SetCovariance(covariance, result.cam_from_lidar, &result);
  return result;
}

}  // namespace colmap_lidar
