#include "bridge/pipeline/stereo_alignment_report.h"

#include <vector>

namespace colmap_lidar {
namespace {

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

}  // namespace colmap_lidar
