#include "bridge/pipeline/vertical_alignment_step.h"

#include "colmap_ext/logging.h"
#include "lidar/plot.h"

#include <iomanip>
#include <iostream>
#include <sstream>

namespace colmap_lidar {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
// [rad^2, m^2] of what the vertical alignment does not measure: no information next to the other
// terms, and a covariance that stays well conditioned
constexpr double kUnmeasuredVariance = 1.0;

std::vector<double> Degrees(const Eigen::VectorXd& radians) {
  std::vector<double> degrees(radians.size());
  for (int k = 0; k < radians.size(); ++k) degrees[k] = radians(k) * kRadToDeg;
  return degrees;
}

// "+x", "-z" etc.: the camera axis nearest to `axis`.
std::string NearestCameraAxis(const Eigen::Vector3d& axis) {
  int k = 0;
  axis.cwiseAbs().maxCoeff(&k);
  return std::string(axis(k) < 0 ? "-" : "+") + "xyz"[k];
}

}  // namespace

VerticalAlignment MeasureStationVerticals(const StationDataset& dataset,
                                          const colmap::Reconstruction& reconstruction,
                                          const LoadedJointData& loaded,
                                          const colmap::Rigid3d& cam_from_lidar,
                                          const ObservabilityOptions& observability) {
  std::vector<VerticalStationInput> inputs;
  for (const auto& [image_id, cloud] : loaded.data.clouds) {
    // The dataset's own image file: a user's database may name its images otherwise.
    const size_t station = loaded.station_of_image.at(image_id);
    inputs.push_back({dataset.stations[station],
                      dataset.LeftImagePath(station),
                      &reconstruction.Camera(reconstruction.Image(image_id).CameraId()),
                      &cloud->cloud,
                      &cloud->curvature});
  }
  const MotionAnalysis motion = AnalyseMotion(reconstruction, observability);
  const Eigen::Vector3d up_in_lidar_guess =
      motion.common_axis_in_cam.isZero()
          ? Eigen::Vector3d::UnitZ()
          : Eigen::Vector3d(cam_from_lidar.rotation.inverse() * motion.common_axis_in_cam);
  const VerticalAlignmentOptions options;
  const VerticalAlignment alignment =
      MeasureVerticalAlignment(inputs, cam_from_lidar.rotation, up_in_lidar_guess, options);
  std::ostringstream line;  // std::cout may hold a fixed precision of 1
  line << "Vertical alignment (walls and vertical image edges): " << alignment.message;
  if (alignment.valid) {
    line << std::setprecision(3) << "; correction about the camera axes "
         << (alignment.axes * alignment.correction).transpose() * kRadToDeg
         << " deg, sigma along its two axes "
         << alignment.covariance.diagonal().cwiseSqrt().transpose() * kRadToDeg << " deg";
  }
  std::cout << line.str() << std::endl;
  return alignment;
}

ExtrinsicMeasurement VerticalAlignmentMeasurement(const VerticalAlignment& alignment,
                                                  const colmap::Rigid3d& cam_from_lidar) {
  THROW_CHECK(alignment.valid);
  ExtrinsicMeasurement measurement;
  measurement.source = "vertical alignment";
  measurement.cam_from_lidar = cam_from_lidar;
  measurement.cam_from_lidar.rotation = alignment.Corrected(cam_from_lidar.rotation);
  measurement.covariance.setZero();
  measurement.covariance.topLeftCorner<3, 3>() = alignment.RotationCovariance(kUnmeasuredVariance);
  measurement.covariance.bottomRightCorner<3, 3>() =
      kUnmeasuredVariance * Eigen::Matrix3d::Identity();
  return measurement;
}

nlohmann::json VerticalAlignmentJson(const VerticalAlignment& alignment) {
  nlohmann::json json;
  json["valid"] = alignment.valid;
  json["message"] = alignment.message;
  json["measured_axes_in_cam"] = {
      {alignment.axes(0, 0), alignment.axes(1, 0), alignment.axes(2, 0)},
      {alignment.axes(0, 1), alignment.axes(1, 1), alignment.axes(2, 1)}};
  json["correction_deg"] = Degrees(alignment.correction);
  json["sigma_deg"] = Degrees(alignment.covariance.diagonal().cwiseSqrt());
  json["station_scatter_deg"] = std::sqrt(alignment.station_variance) * kRadToDeg;
  json["serial_correlation"] = alignment.serial_correlation;
  json["effective_stations"] = alignment.effective_stations;
  json["significant"] = alignment.Significant();
  nlohmann::json stations = nlohmann::json::array();
  for (const StationVertical& station : alignment.stations) {
    stations.push_back({{"name", station.name},
                        {"used", station.used},
                        {"lidar_walls", station.up_in_lidar.num_inliers},
                        {"lidar_rms_deg", station.up_in_lidar.rms_deg},
                        {"image_segments", station.num_segments},
                        {"image_vertical_segments", station.up_in_cam.num_inliers},
                        {"image_rms_deg", station.up_in_cam.rms_deg},
                        {"residual_deg", {station.residual_deg(0), station.residual_deg(1)}}});
  }
  json["stations"] = stations;
  return json;
}

void WriteVerticalAlignmentPlot(const std::string& path, const VerticalAlignment& alignment) {
  PlotSeries first{"about " + NearestCameraAxis(alignment.axes.col(0)), {}, {}};
  PlotSeries second{"about " + NearestCameraAxis(alignment.axes.col(1)), {}, {}};
  for (size_t k = 0; k < alignment.stations.size(); ++k) {
    if (!alignment.stations[k].used) continue;
    first.x.push_back(static_cast<double>(k));
    first.y.push_back(alignment.stations[k].residual_deg(0));
    second.x.push_back(static_cast<double>(k));
    second.y.push_back(alignment.stations[k].residual_deg(1));
  }
  LinePlotOptions options;
  options.title = "Vertical alignment: walls vs. vertical image edges (camera axes)";
  options.x_label = "station";
  options.y_label = "residual [deg]";
  WriteLinePlotPng(path, {first, second}, options);
}

}  // namespace colmap_lidar
