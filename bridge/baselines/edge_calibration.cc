#include "bridge/baselines/edge_calibration.h"

#include "colmap_ext/logging.h"

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include <array>
#include <chrono>
#include <cmath>

namespace colmap_lidar {
namespace {

constexpr int kGridSize = 729;  // 3^6

// The grid point k in {-1, 0, 1}^6 (rotation vector in the camera frame, then translation), applied
// on the left: cam_from_lidar' = delta * cam_from_lidar. k = 364 is the centre.
colmap::Rigid3d GridNeighbour(const colmap::Rigid3d& cam_from_lidar,
                              int k,
                              double rotation_step_rad,
                              double translation_step_m) {
  std::array<int, 6> offset;
  for (int axis = 0; axis < 6; ++axis, k /= 3) offset[axis] = k % 3 - 1;
  const Eigen::Vector3d rotation =
      rotation_step_rad * Eigen::Vector3d(offset[0], offset[1], offset[2]);
  const Eigen::Vector3d translation =
      translation_step_m * Eigen::Vector3d(offset[3], offset[4], offset[5]);
  colmap::Rigid3d delta;
  if (rotation.norm() > 0) {
    delta.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(rotation.norm(), rotation.normalized()));
  }
  delta.translation = translation;
  return delta * cam_from_lidar;
}

constexpr int kCentre = 364;

// J at every grid point about `centre`.
std::array<double, kGridSize> GridObjectives(const std::vector<EdgeStation>& stations,
                                             const colmap::Rigid3d& centre,
                                             double rotation_step_rad,
                                             double translation_step_m,
                                             double min_depth_m) {
  std::array<double, kGridSize> objectives;
#pragma omp parallel for schedule(dynamic, 8)
  for (int k = 0; k < kGridSize; ++k) {
    objectives[k] = EdgeObjective(
        stations, GridNeighbour(centre, k, rotation_step_rad, translation_step_m), min_depth_m);
  }
  return objectives;
}

}  // namespace

bool EdgeCalibrationOptions::Check() const {
  CHECK_OPTION(discontinuities.Check());
  CHECK_OPTION(transform.Check());
  CHECK_OPTION(!rotation_steps_deg.empty());
  CHECK_OPTION_EQ(rotation_steps_deg.size(), translation_steps_m.size());
  for (size_t level = 0; level < rotation_steps_deg.size(); ++level) {
    CHECK_OPTION_GT(rotation_steps_deg[level], 0);
    CHECK_OPTION_GT(translation_steps_m[level], 0);
  }
  CHECK_OPTION_GE(max_moves_per_level, 1);
  CHECK_OPTION_GT(min_depth_m, 0);
  return true;
}

EdgeStation PrepareEdgeStation(const std::string& name,
                               const cv::Mat& image,
                               const colmap::Camera& camera,
                               const std::vector<Eigen::Vector3d>& points_in_lidar,
                               const EdgeCalibrationOptions& options) {
  THROW_CHECK(options.Check());
  THROW_CHECK_EQ(image.cols, static_cast<int>(camera.width)) << "station " << name;
  THROW_CHECK_EQ(image.rows, static_cast<int>(camera.height)) << "station " << name;
  EdgeStation station;
  station.name = name;
  station.camera = camera;
  station.transform = InverseDistanceTransform(EdgeImage(image, options.transform.blur_sigma_px),
                                               options.transform);
  station.discontinuities = DetectDepthDiscontinuities(points_in_lidar, options.discontinuities);
  return station;
}

double StationEdgeObjective(const EdgeStation& station,
                            const colmap::Rigid3d& cam_from_lidar,
                            double min_depth_m) {
  const Eigen::Matrix3x4d cam_from_lidar_matrix = cam_from_lidar.ToMatrix();
  const cv::Mat& transform = station.transform;
  double objective = 0;
  for (const DepthDiscontinuity& d : station.discontinuities) {
    const Eigen::Vector3d point_in_cam = cam_from_lidar_matrix * d.point_in_lidar.homogeneous();
    if (point_in_cam.z() < min_depth_m) continue;
    const Eigen::Vector2d xy = station.camera.ImgFromCam(point_in_cam.hnormalized());
    const int col = static_cast<int>(std::floor(xy.x()));
    const int row = static_cast<int>(std::floor(xy.y()));
    if (col < 0 || row < 0 || col >= transform.cols || row >= transform.rows) continue;
    objective += d.score * transform.at<float>(row, col);
  }
  return objective;
}

double EdgeObjective(const std::vector<EdgeStation>& stations,
                     const colmap::Rigid3d& cam_from_lidar,
                     double min_depth_m) {
  double objective = 0;
  for (const EdgeStation& station : stations) {
    objective += StationEdgeObjective(station, cam_from_lidar, min_depth_m);
  }
  return objective;
}

EdgeCalibrationResult CalibrateFromEdges(const std::vector<EdgeStation>& stations,
                                         const colmap::Rigid3d& initial_cam_from_lidar,
                                         const EdgeCalibrationOptions& options) {
  THROW_CHECK(options.Check());
  THROW_CHECK(!stations.empty());
  const auto start = std::chrono::steady_clock::now();
  EdgeCalibrationResult result;
  result.cam_from_lidar = initial_cam_from_lidar;
  result.initial_objective = EdgeObjective(stations, initial_cam_from_lidar, options.min_depth_m);
  result.objective_history.push_back(result.initial_objective);
  std::array<double, kGridSize> objectives{};
  for (size_t level = 0; level < options.rotation_steps_deg.size(); ++level) {
    const double rotation_step = options.rotation_steps_deg[level] * M_PI / 180;
    const double translation_step = options.translation_steps_m[level];
    int moves = 0;
    while (true) {
      objectives = GridObjectives(
          stations, result.cam_from_lidar, rotation_step, translation_step, options.min_depth_m);
      int best = kCentre;
      for (int k = 0; k < kGridSize; ++k) {
        if (objectives[k] > objectives[best]) best = k;
      }
      if (best == kCentre) break;
      if (moves == options.max_moves_per_level) {
        result.converged = false;
        break;
      }
      result.cam_from_lidar =
          GridNeighbour(result.cam_from_lidar, best, rotation_step, translation_step);
      result.objective_history.push_back(objectives[best]);
      ++moves;
    }
    result.moves.push_back(moves);
  }
  // F_c on the finest grid about the result (`objectives` holds it: the last level ended there).
  result.final_objective = objectives[kCentre];
  int lower = 0;
  for (int k = 0; k < kGridSize; ++k) lower += k != kCentre && objectives[k] < objectives[kCentre];
  result.fraction_lower = lower / double(kGridSize - 1);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

cv::Mat EdgeOverlay(const EdgeStation& station,
                    const colmap::Rigid3d& before,
                    const colmap::Rigid3d& after,
                    double min_depth_m) {
  cv::Mat grey, overlay;
  double largest = 0;
  cv::minMaxLoc(station.transform, nullptr, &largest);
  station.transform.convertTo(grey, CV_8U, largest > 0 ? 255.0 / largest : 0.0);
  cv::cvtColor(grey, overlay, cv::COLOR_GRAY2BGR);
  for (const auto& [cam_from_lidar, colour] :
       {std::pair{before, cv::Scalar(0, 0, 255)}, std::pair{after, cv::Scalar(0, 255, 0)}}) {
    for (const DepthDiscontinuity& d : station.discontinuities) {
      const Eigen::Vector3d point_in_cam = cam_from_lidar * d.point_in_lidar;
      if (point_in_cam.z() < min_depth_m) continue;
      const Eigen::Vector2d xy = station.camera.ImgFromCam(point_in_cam.hnormalized());
      cv::circle(overlay, cv::Point2d(xy.x(), xy.y()), 1, colour, cv::FILLED);
    }
  }
  return overlay;
}

}  // namespace colmap_lidar
