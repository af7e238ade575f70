// A joint problem built directly from the simulator, without SIFT or images: landmarks are visible
// surface points of the scene, keypoints their projections (plus optional Gaussian pixel noise), depth
// priors their true z-depths (plus optional noise of sigma_d), LiDAR clouds simulated scans (optional
// range noise). Starting poses, landmarks and cam_from_lidar are perturbed (seeded). For tests that
// need the joint adjuster's accuracy or its reported uncertainty against the truth, and for
// plan_survey, which predicts the calibration of planned stations before anyone goes to the field.
#pragma once

#include "bridge/joint/joint_adjuster.h"
#include "bridge/simulation/renderer.h"
#include "bridge/simulation/scene.h"
#include "bridge/simulation/sensor_pod.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/point_cloud.h"
#include "lidar/station_cloud.h"

#include "colmap/scene/reconstruction.h"

#include <functional>
#include <memory>
#include <vector>

namespace colmap_lidar {
namespace sim {

struct SyntheticJointOptions {
  // Stations of MakeSyntheticJointProblem(scene, options): sim::MakeStations' (not used when the
  // stations are given).
  int num_stations = 8;
  sim::Motion motion = sim::Motion::kTwoAxes;
  uint64_t station_seed = 3;
  // Landmarks: every `landmark_stride`-th surface sample at this spacing.
  double landmark_spacing_m = 0.04;
  int landmark_stride = 3;
  size_t lidar_points = 300000;
  double lidar_range_noise_m = 0;
  // The sensor pod: cameras (the left one's model and size) and the true cam_from_lidar.
  StationRig rig = sim::MakeStereoRig(1.0);
  colmap::Rigid3d true_cam_from_lidar = sim::TrueCamFromLidar();
  // Keypoint noise [px] and depth-prior noise in units of each prior's sigma_d.
  double pixel_noise = 0;
  double depth_noise_sigmas = 0;
  // A relative scale error common to every depth prior (a stereo calibration error).
  double depth_scale_error = 0;
  // A disparity bias field common to every depth prior [px]: offset, slope per normalised image x
  // and y (colmap_ext/depth_prior_cost.h).
  Eigen::Vector3d disparity_bias_px = Eigen::Vector3d::Zero();
  // sigma_p of sigma_d = d^2/(b f) sigma_p.
  double depth_sigma_pixels = 1.0;
  // Start: poses (all but the first), landmarks and cam_from_lidar perturbed.
  double pose_rotation_deg = 0.3;
  double pose_translation_m = 0.01;
  double landmark_offset_m = 0.01;
  double extrinsic_rotation_deg = 5.0;
  double extrinsic_translation_m = 0.10;
  uint64_t noise_seed = 11;
};

struct SyntheticJointProblem {
  colmap::Reconstruction reconstruction;
  JointProblemData data;
  std::vector<std::unique_ptr<StationCloud>> clouds;  // data.clouds points here
  std::vector<colmap::Rigid3d> true_cam_from_world;   // image_id = index + 1
  colmap::Rigid3d true_cam_from_lidar;
  colmap::Rigid3d cam_from_lidar;  // the perturbed start
};

// What the problem is built from: the structure's surface, its occlusions and LiDAR scans of it.
struct SyntheticWorld {
  // Points on the structure's surface about `spacing` apart (the landmark candidates).
  std::function<PointCloud(double spacing)> sample_surface;
  // Whether nothing hides `point` from a camera at `center`.
  std::function<bool(const Eigen::Vector3d& center, const Eigen::Vector3d& point)> visible;
  // A LiDAR scan from `world_from_lidar`, points in the LiDAR frame.
  std::function<PointCloud(const colmap::Rigid3d& world_from_lidar, const LidarOptions& options)>
      scan;
};

// The simulator's scene (ray-cast; the scene must outlive the world).
SyntheticWorld WorldOfScene(const Scene& scene);

// The problem for given true stations (cam_from_world of the left camera) of any world. Every station
// pair is a LiDAR pair.
std::unique_ptr<SyntheticJointProblem> MakeSyntheticJointProblem(
    const SyntheticWorld& world,
    const std::vector<colmap::Rigid3d>& true_cam_from_world,
    const SyntheticJointOptions& options);

// The problem for the stations of sim::MakeStations(scene, num_stations, motion, station_seed).
std::unique_ptr<SyntheticJointProblem> MakeSyntheticJointProblem(
    const Scene& scene, const SyntheticJointOptions& options);

// The problem for given true stations of the scene.
std::unique_ptr<SyntheticJointProblem> MakeSyntheticJointProblem(
    const Scene& scene,
    const std::vector<colmap::Rigid3d>& true_cam_from_world,
    const SyntheticJointOptions& options);

}  // namespace sim
}  // namespace colmap_lidar
