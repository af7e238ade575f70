#include "bridge/exe/stereo_alignment_report.h"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace colmap_lidar {
namespace {

constexpr char kBlock[] = "stereo_alignment";
constexpr char kPose[] = "cam_from_lidar";
constexpr char kCovariance[] = "covariance_in_cam";

template <typename Matrix>
std::vector<double> RowMajor(const Matrix& matrix) {
  std::vector<double> values;
  for (int row = 0; row < matrix.rows(); ++row) {
    for (int col = 0; col < matrix.cols(); ++col) values.push_back(matrix(row, col));
  }
  return values;
}

// `size` finite numbers at block[key], or an error naming the file and the key.
std::vector<double> Numbers(const nlohmann::json& block,
                            const char* key,
                            size_t size,
                            const std::string& path) {
  const std::string where = path + ": " + kBlock + "." + key;
  if (!block.contains(key) || !block[key].is_array() || block[key].size() != size) {
    throw std::runtime_error(where + " must be an array of " + std::to_string(size) + " numbers");
  }
  std::vector<double> values;
  for (const nlohmann::json& value : block[key]) {
    if (!value.is_number() || !std::isfinite(value.get<double>())) {
      throw std::runtime_error(where + " holds something that is not a finite number");
    }
    values.push_back(value.get<double>());
  }
  return values;
}

}  // namespace

nlohmann::json StereoAlignmentJson(const StereoLidarAlignment& alignment) {
  const ExtrinsicAlignmentResult& r = alignment.result;
  const colmap::Rigid3d& pose = alignment.cam_from_lidar;
  return {{"used", alignment.used},
          {"message", alignment.message},
          {"stations", alignment.num_stations},
          {"stereo_points", r.num_points},
          {"associations", r.num_associations},
          {"rms_mm", 1000 * r.rms_m},
          {"rms_sigmas", r.rms_sigmas},
          {"iterations", r.iterations},
          {"converged", r.converged},
          {"rotation_change_deg", alignment.rotation_change_deg},
          {"translation_change_mm", 1000 * alignment.translation_change_m},
          {"sigma_rotation_deg_in_cam", RowMajor(r.sigma_rotation_deg)},
          {"sigma_translation_mm_in_cam", RowMajor(Eigen::Vector3d(1000 * r.sigma_translation_m))},
          {"constraint_ratios", RowMajor(r.constraint_ratios)},
          {"directions_held_at_start", r.num_weak_directions},
          {"covariance_clustered_by_station", r.station_clustered},
          {"stations_with_associations", r.num_station_clusters},
          {kPose,
           {pose.rotation.w(),
            pose.rotation.x(),
            pose.rotation.y(),
            pose.rotation.z(),
            pose.translation.x(),
            pose.translation.y(),
            pose.translation.z()}},
          {kCovariance, RowMajor(r.covariance_in_cam)}};
}

std::optional<ExtrinsicMeasurement> ReadStereoAlignmentMeasurement(
    const nlohmann::json& initialization, const std::string& path) {
  if (!initialization.contains(kBlock)) return std::nullopt;
  const nlohmann::json& block = initialization[kBlock];
  if (!block.is_object() || !block.contains("used") || !block["used"].is_boolean()) {
    throw std::runtime_error(path + ": " + kBlock + " must be an object with a boolean \"used\"");
  }
  if (!block["used"].get<bool>()) return std::nullopt;
  // A formal covariance (too few stations to cluster) is a lower bound: as a measurement it would
  // outweigh the joint problem's own data.
  if (!block.value("covariance_clustered_by_station", false)) return std::nullopt;
  const std::vector<double> pose = Numbers(block, kPose, 7, path);
  const std::vector<double> covariance = Numbers(block, kCovariance, 36, path);
  ExtrinsicMeasurement measurement;
  measurement.cam_from_lidar.rotation =
      Eigen::Quaterniond(pose[0], pose[1], pose[2], pose[3]).normalized();
  measurement.cam_from_lidar.translation = Eigen::Vector3d(pose[4], pose[5], pose[6]);
  // Its marginal sigmas per camera axis, without the correlations. The alignment's errors are mostly
  // shared by all stations and do not follow the correlations its information predicts; as a
  // correlated measurement it would drag the roll along each time the LiDAR term corrects the pitch.
  const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> full(covariance.data());
  if (!(full.diagonal().minCoeff() > 0)) {
    throw std::runtime_error(path + ": " + kBlock + "." + kCovariance +
                             " has a variance that is not positive on its diagonal");
  }
  measurement.covariance = full.diagonal().asDiagonal();
  measurement.source = "stereo-LiDAR alignment";
  return measurement;
}

}  // namespace colmap_lidar
