#include "lidar/odometry_registration.h"

#include "lidar/cloud_io.h"

#include <chrono>
#include <stdexcept>

namespace colmap_lidar {
namespace {

// The edge of frame k-1 (target) and k (source) from the odometry.
LidarEdge OdometryEdge(const std::vector<OdometryFrame>& frames, size_t k) {
  const OdometryFrame& frame = frames[k];
  LidarEdge edge;
  edge.target = k - 1;
  edge.source = k;
  edge.target_from_source = frames[k - 1].world_from_lidar.inverse() * frame.world_from_lidar;
  PairRegistration& registration = edge.registration;
  registration.target_from_source = edge.target_from_source;
  registration.num_inliers = frame.num_correspondences;
  registration.overlap = frame.num_source_points ? static_cast<double>(frame.num_correspondences) /
                                                       frame.num_source_points
                                                 : 0.0;
  registration.rmse = frame.plane_rms_m;
  registration.converged = frame.converged;
  registration.hessian = frame.information;
  registration.constraints = frame.constraints;
  registration.degenerate = frame.degenerate;
  registration.accepted = true;
  edge.odometry = true;
  return edge;
}

}  // namespace

OdometryRegistration RegisterSweepsByOdometry(const std::vector<std::string>& cloud_paths,
                                              const std::vector<double>& clock,
                                              const LidarOdometryOptions& options,
                                              const std::function<void(size_t, size_t)>& progress) {
  if (clock.size() != cloud_paths.size()) {
    throw std::invalid_argument("RegisterSweepsByOdometry: one clock value per cloud is needed");
  }
  OdometryRegistration result;
  LidarOdometry odometry(options);
  for (size_t k = 0; k < cloud_paths.size(); ++k) {
    const PointCloud sweep = ReadStationCloud(cloud_paths[k]);
    const auto start = std::chrono::steady_clock::now();
    try {
      odometry.RegisterFrame(sweep, clock[k]);
    } catch (const std::exception& error) {
      throw std::runtime_error(cloud_paths[k] + ": " + error.what());
    }
    result.seconds_registering +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (progress) progress(k + 1, cloud_paths.size());
  }
  result.frames = odometry.Frames();
  LidarGraph& graph = result.graph;
  for (const OdometryFrame& frame : result.frames)
    graph.world_from_lidar.push_back(frame.world_from_lidar);
  graph.component.assign(result.frames.size(), 0);
  graph.num_components = result.frames.empty() ? 0 : 1;
  for (size_t k = 1; k < result.frames.size(); ++k) {
    graph.edges.push_back(OdometryEdge(result.frames, k));
  }
  return result;
}

}  // namespace colmap_lidar
