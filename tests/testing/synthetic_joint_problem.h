// A small joint problem built directly from the simulator, without SIFT or images: landmarks are
// visible surface points of the scene, keypoints their projections (plus optional Gaussian pixel
// noise), depth priors their true z-depths (plus optional noise of sigma_d), LiDAR clouds simulated
// scans (optional range noise). Starting poses, landmarks and cam_from_lidar are perturbed (seeded).
// For tests that need the joint adjuster's accuracy or its reported uncertainty against the truth.
#pragma once

#include "bridge/joint_adjuster.h"
#include "colmap_ext/depth_prior_extractor.h"
#include "lidar/station_cloud.h"
#include "tests/simulator/renderer.h"
#include "tests/simulator/scene.h"
#include "tests/simulator/sensor_pod.h"

#include "colmap/scene/reconstruction.h"

#include <memory>
#include <random>
#include <vector>

namespace colmap_lidar {
namespace testing {

struct SyntheticJointOptions {
  int num_stations = 8;
  sim::Motion motion = sim::Motion::kTwoAxes;
  uint64_t station_seed = 3;
  // Landmarks: every `landmark_stride`-th surface sample at this spacing.
  double landmark_spacing_m = 0.04;
  int landmark_stride = 3;
  size_t lidar_points = 300000;
  double lidar_range_noise_m = 0;
  // Keypoint noise [px] and depth-prior noise in units of each prior's sigma_d.
  double pixel_noise = 0;
  double depth_noise_sigmas = 0;
  // A relative scale error common to every depth prior (a stereo calibration error).
  double depth_scale_error = 0;
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

namespace internal {

inline bool Occluded(const sim::Scene& scene,
                     const Eigen::Vector3d& center,
                     const Eigen::Vector3d& point) {
  sim::RayHit hit;
  const double distance = (point - center).norm();
  return scene.Intersect(center, (point - center) / distance, distance + 1, &hit) &&
         hit.t < distance - 1e-3;
}

}  // namespace internal

inline std::unique_ptr<SyntheticJointProblem> MakeSyntheticJointProblem(
    const sim::Scene& scene, const SyntheticJointOptions& options) {
  auto problem = std::make_unique<SyntheticJointProblem>();
  const StationRig rig = sim::MakeStereoRig(1.0);
  problem->true_cam_from_world =
      sim::MakeStations(scene, options.num_stations, options.motion, options.station_seed);
  problem->true_cam_from_lidar = sim::TrueCamFromLidar();
  const std::vector<colmap::Rigid3d>& truth = problem->true_cam_from_world;
  std::mt19937 rng(options.noise_seed);
  std::normal_distribution<double> normal(0, 1);

  colmap::Camera camera = rig.left;
  camera.camera_id = 1;
  problem->reconstruction.AddCamera(camera);
  // Landmarks seen (unoccluded, inside the image) by at least two stations.
  std::vector<std::vector<Eigen::Vector2d>> points2D(truth.size());
  std::vector<std::vector<std::pair<size_t, size_t>>> tracks;  // (station, point2D index)
  std::vector<Eigen::Vector3d> landmarks;
  const PointCloud surface = scene.SampleObjectSurface(options.landmark_spacing_m);
  for (size_t p = 0; p < surface.Size(); p += options.landmark_stride) {
    const Eigen::Vector3d& point = surface.points[p];
    std::vector<std::pair<size_t, size_t>> track;
    for (size_t s = 0; s < truth.size(); ++s) {
      const Eigen::Vector3d in_cam = truth[s] * point;
      if (in_cam.z() < 0.5) continue;
      const Eigen::Vector2d xy = camera.ImgFromCam(in_cam.hnormalized());
      if (xy.x() < 1 || xy.y() < 1 || xy.x() > camera.width - 1 || xy.y() > camera.height - 1 ||
          internal::Occluded(scene, colmap::Inverse(truth[s]).translation, point)) {
        continue;
      }
      track.emplace_back(s, points2D[s].size());
      points2D[s].push_back(xy + options.pixel_noise * Eigen::Vector2d(normal(rng), normal(rng)));
    }
    if (track.size() >= 2) {
      tracks.push_back(track);
      landmarks.push_back(point);
    } else {
      for (const auto& [s, index] : track) points2D[s].pop_back();
    }
  }
  for (size_t s = 0; s < truth.size(); ++s) {
    colmap::Image image;
    image.SetImageId(static_cast<colmap::image_t>(s + 1));
    image.SetName("left/" + std::to_string(s) + ".png");
    image.SetCameraId(1);
    image.SetPoints2D(points2D[s]);
    image.CamFromWorld() = s == 0 ? truth[s]
                                  : sim::PerturbPose(truth[s],
                                                     options.pose_rotation_deg,
                                                     options.pose_translation_m,
                                                     100 + s + 1000 * options.noise_seed);
    problem->reconstruction.AddImage(image);
    problem->reconstruction.RegisterImage(image.ImageId());
  }
  const double baseline = rig.BaselineMeters();
  const double focal = rig.left.params[0];
  for (size_t k = 0; k < landmarks.size(); ++k) {
    colmap::Track track;
    for (const auto& [s, index] : tracks[k]) {
      const colmap::image_t image_id = static_cast<colmap::image_t>(s + 1);
      track.AddElement(image_id, static_cast<colmap::point2D_t>(index));
      const double depth = (truth[s] * landmarks[k]).z();
      const double sigma = DepthSigma(depth, baseline, focal, options.depth_sigma_pixels);
      problem->data.depth_priors[image_id][index] = {
          static_cast<colmap::point2D_t>(index),
          depth * (1 + options.depth_scale_error) +
              options.depth_noise_sigmas * sigma * normal(rng),
          sigma};
    }
    problem->reconstruction.AddPoint3D(
        landmarks[k] +
            options.landmark_offset_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)),
        track);
  }

  StationCloudOptions cloud_options;
  cloud_options.compute_features = false;
  for (size_t s = 0; s < truth.size(); ++s) {
    sim::LidarOptions lidar;
    lidar.num_points = options.lidar_points;
    lidar.range_noise_m = options.lidar_range_noise_m;
    lidar.seed = s + 1000 * options.noise_seed;
    const PointCloud scan =
        sim::ScanLidar(scene, colmap::Inverse(truth[s]) * problem->true_cam_from_lidar, lidar);
    problem->clouds.push_back(PrepareStationCloud(scan, cloud_options));
    problem->data.clouds[static_cast<colmap::image_t>(s + 1)] = problem->clouds.back().get();
    for (size_t t = s + 1; t < truth.size(); ++t) problem->data.pairs.emplace_back(s + 1, t + 1);
  }
  problem->cam_from_lidar = sim::PerturbPose(problem->true_cam_from_lidar,
                                             options.extrinsic_rotation_deg,
                                             options.extrinsic_translation_m,
                                             42 + options.noise_seed);
  return problem;
}

// Rotation error [deg] about the camera axes and translation error [mm] of an estimated cam_from_lidar,
// as the 6-vector the uncertainty reports (rotation vector of estimate * inverse(truth)).
inline Eigen::Matrix<double, 6, 1> ExtrinsicError(const colmap::Rigid3d& estimate,
                                                  const colmap::Rigid3d& truth) {
  Eigen::Matrix<double, 6, 1> error;
  const Eigen::AngleAxisd rotation(estimate.rotation * truth.rotation.inverse());
  error.head<3>() = rotation.angle() * rotation.axis() * 180 / M_PI;
  error.tail<3>() = 1000 * (estimate.translation - truth.translation);
  return error;
}

}  // namespace testing
}  // namespace colmap_lidar
