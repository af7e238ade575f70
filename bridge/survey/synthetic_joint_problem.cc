#include "bridge/survey/synthetic_joint_problem.h"

#include "bridge/simulation/renderer.h"
#include "colmap_ext/depth_prior_extractor.h"

#include <random>

namespace colmap_lidar {
namespace sim {
namespace {

bool Occluded(const Scene& scene, const Eigen::Vector3d& center, const Eigen::Vector3d& point) {
  RayHit hit;
  const double distance = (point - center).norm();
  return scene.Intersect(center, (point - center) / distance, distance + 1, &hit) &&
         hit.t < distance - 1e-3;
}

}  // namespace

SyntheticWorld WorldOfScene(const Scene& scene) {
  SyntheticWorld world;
  world.sample_surface = [&scene](double spacing) { return scene.SampleObjectSurface(spacing); };
  world.visible = [&scene](const Eigen::Vector3d& center, const Eigen::Vector3d& point) {
    return !Occluded(scene, center, point);
  };
  world.scan = [&scene](const colmap::Rigid3d& world_from_lidar, const LidarOptions& options) {
    return ScanLidar(scene, world_from_lidar, options);
  };
  return world;
}

std::unique_ptr<SyntheticJointProblem> MakeSyntheticJointProblem(
    const Scene& scene,
    const std::vector<colmap::Rigid3d>& true_cam_from_world,
    const SyntheticJointOptions& options) {
  return MakeSyntheticJointProblem(WorldOfScene(scene), true_cam_from_world, options);
}

namespace {

// The noise source: one distribution throughout (it caches a second value between draws), so that a
// seed gives the same problem however the steps are split.
struct Noise {
  std::mt19937 rng;
  std::normal_distribution<double> normal{0, 1};
  double Draw() { return normal(rng); }
};

// Keypoints of the landmarks seen (unoccluded, inside the image) by at least two stations, with pixel
// noise in landmark order.
struct Observations {
  std::vector<std::vector<Eigen::Vector2d>> points2D;          // per station
  std::vector<std::vector<std::pair<size_t, size_t>>> tracks;  // (station, point2D index)
  std::vector<Eigen::Vector3d> landmarks;
};

Observations ObserveLandmarks(const SyntheticWorld& world,
                              const std::vector<colmap::Rigid3d>& truth,
                              const colmap::Camera& camera,
                              const SyntheticJointOptions& options,
                              Noise* noise) {
  Observations seen;
  seen.points2D.resize(truth.size());
  const PointCloud surface = world.sample_surface(options.landmark_spacing_m);
  for (size_t p = 0; p < surface.Size(); p += options.landmark_stride) {
    const Eigen::Vector3d& point = surface.points[p];
    std::vector<std::pair<size_t, size_t>> track;
    for (size_t s = 0; s < truth.size(); ++s) {
      const Eigen::Vector3d in_cam = truth[s] * point;
      if (in_cam.z() < 0.5) continue;
      const Eigen::Vector2d xy = camera.ImgFromCam(in_cam.hnormalized());
      if (xy.x() < 1 || xy.y() < 1 || xy.x() > camera.width - 1 || xy.y() > camera.height - 1 ||
          !world.visible(colmap::Inverse(truth[s]).translation, point)) {
        continue;
      }
      track.emplace_back(s, seen.points2D[s].size());
      seen.points2D[s].push_back(xy + options.pixel_noise *
                                          Eigen::Vector2d(noise->Draw(), noise->Draw()));
    }
    if (track.size() >= 2) {
      seen.tracks.push_back(track);
      seen.landmarks.push_back(point);
    } else {
      for (const auto& [s, index] : track) seen.points2D[s].pop_back();
    }
  }
  return seen;
}

// The registered images: the first at its true pose, the others perturbed (seeded).
void AddImages(const std::vector<colmap::Rigid3d>& truth,
               const Observations& seen,
               const SyntheticJointOptions& options,
               colmap::Reconstruction* reconstruction) {
  for (size_t s = 0; s < truth.size(); ++s) {
    colmap::Image image;
    image.SetImageId(static_cast<colmap::image_t>(s + 1));
    image.SetName("left/" + std::to_string(s) + ".png");
    image.SetCameraId(1);
    image.SetPoints2D(seen.points2D[s]);
    image.CamFromWorld() = s == 0 ? truth[s]
                                  : PerturbPose(truth[s],
                                                options.pose_rotation_deg,
                                                options.pose_translation_m,
                                                100 + s + 1000 * options.noise_seed);
    reconstruction->AddImage(image);
    reconstruction->RegisterImage(image.ImageId());
  }
}

// The z-depth of `point_in_cam` as a stereo rig with the disparity bias field
// options.disparity_bias_px measures it: 1/d + (1, x, y) . delta / (b f).
double BiasedDepth(const Eigen::Vector3d& point_in_cam, const SyntheticJointOptions& options) {
  const Eigen::Vector3d basis(
      1, point_in_cam.x() / point_in_cam.z(), point_in_cam.y() / point_in_cam.z());
  const double baseline_focal = options.rig.BaselineFocal();
  return 1 / (1 / point_in_cam.z() + options.disparity_bias_px.dot(basis) / baseline_focal);
}

// The landmarks (offset by noise) with their tracks, and a depth prior per observation for a stereo
// rig (true z-depth, noise of its own sigma_d, the common scale error and the disparity bias field).
void AddLandmarks(const Observations& seen,
                  const SyntheticJointOptions& options,
                  Noise* noise,
                  SyntheticJointProblem* problem) {
  const StationRig& rig = options.rig;
  const std::vector<colmap::Rigid3d>& truth = problem->true_cam_from_world;
  for (size_t k = 0; k < seen.landmarks.size(); ++k) {
    colmap::Track track;
    for (const auto& [s, index] : seen.tracks[k]) {
      const colmap::image_t image_id = static_cast<colmap::image_t>(s + 1);
      track.AddElement(image_id, static_cast<colmap::point2D_t>(index));
      if (!rig.IsStereo()) continue;  // a monocular rig has no depth priors
      const double depth = (truth[s] * seen.landmarks[k]).z();
      const double sigma =
          DepthSigma(depth, rig.BaselineMeters(), rig.left.params[0], options.depth_sigma_pixels);
      problem->data.depth_priors[image_id][index] = {
          static_cast<colmap::point2D_t>(index),
          BiasedDepth(truth[s] * seen.landmarks[k], options) * (1 + options.depth_scale_error) +
              options.depth_noise_sigmas * sigma * noise->Draw(),
          sigma};
    }
    problem->reconstruction.AddPoint3D(
        seen.landmarks[k] + options.landmark_offset_m *
                                Eigen::Vector3d(noise->Draw(), noise->Draw(), noise->Draw()),
        track);
  }
}

// A LiDAR scan per station from its true pose; every station pair a LiDAR pair.
void AddLidarScans(const SyntheticWorld& world,
                   const SyntheticJointOptions& options,
                   SyntheticJointProblem* problem) {
  StationCloudOptions cloud_options;
  cloud_options.compute_features = false;
  const std::vector<colmap::Rigid3d>& truth = problem->true_cam_from_world;
  for (size_t s = 0; s < truth.size(); ++s) {
    LidarOptions lidar;
    lidar.num_points = options.lidar_points;
    lidar.range_noise_m = options.lidar_range_noise_m;
    lidar.seed = s + 1000 * options.noise_seed;
    const PointCloud scan =
        world.scan(colmap::Inverse(truth[s]) * problem->true_cam_from_lidar, lidar);
    problem->clouds.push_back(PrepareStationCloud(scan, cloud_options));
    problem->data.clouds[static_cast<colmap::image_t>(s + 1)] = problem->clouds.back().get();
    for (size_t t = s + 1; t < truth.size(); ++t) problem->data.pairs.emplace_back(s + 1, t + 1);
  }
}

}  // namespace

std::unique_ptr<SyntheticJointProblem> MakeSyntheticJointProblem(
    const SyntheticWorld& world,
    const std::vector<colmap::Rigid3d>& true_cam_from_world,
    const SyntheticJointOptions& options) {
  auto problem = std::make_unique<SyntheticJointProblem>();
  problem->true_cam_from_world = true_cam_from_world;
  problem->true_cam_from_lidar = options.true_cam_from_lidar;
  Noise noise{std::mt19937(options.noise_seed)};
  colmap::Camera camera = options.rig.left;
  camera.camera_id = 1;
  problem->reconstruction.AddCamera(camera);
  const Observations seen =
      ObserveLandmarks(world, problem->true_cam_from_world, camera, options, &noise);
  AddImages(problem->true_cam_from_world, seen, options, &problem->reconstruction);
  AddLandmarks(seen, options, &noise, problem.get());
  problem->data.stereo_baseline_focal = options.rig.BaselineFocal();
  AddLidarScans(world, options, problem.get());
  problem->cam_from_lidar = PerturbPose(problem->true_cam_from_lidar,
                                        options.extrinsic_rotation_deg,
                                        options.extrinsic_translation_m,
                                        42 + options.noise_seed);
  return problem;
}

std::unique_ptr<SyntheticJointProblem> MakeSyntheticJointProblem(
    const Scene& scene, const SyntheticJointOptions& options) {
  return MakeSyntheticJointProblem(
      scene,
      MakeStations(scene, options.num_stations, options.motion, options.station_seed),
      options);
}

}  // namespace sim
}  // namespace colmap_lidar
