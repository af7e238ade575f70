// The joint adjuster on exact synthetic observations (noise off): keypoints are true projections,
// depth priors true depths, LiDAR clouds noise-free scans of the same scene. Starting from poses off by
// 0.3 deg / 1 cm, landmarks off by 1 cm and cam_from_lidar off by 5 deg / 10 cm, joint mode must recover
// cam_from_lidar to < 0.01 deg / 0.5 mm and the poses to < 0.5 mm. Uses the C++ API directly.
#include "bridge/joint_adjuster.h"
#include "colmap_ext/depth_prior_extractor.h"
#include "lidar/station_cloud.h"
#include "tests/simulator/renderer.h"
#include "tests/simulator/scene.h"
#include "tests/simulator/sensor_pod.h"

#include "colmap/scene/reconstruction.h"

#include <gtest/gtest.h>

#include <random>

namespace colmap_lidar {
namespace {

double RotationErrorDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a * b.inverse()).angle() * 180 / M_PI;
}

TEST(JointAdjusterExactTest, NoiseFreeRecoversExtrinsicAndPosesFromAFarGuess) {
  const sim::Scene scene = sim::Scene::Create("t_specimen");
  const StationRig rig = sim::MakeStereoRig(1.0);
  const std::vector<colmap::Rigid3d> truth = sim::MakeStations(scene, 8, sim::Motion::kTwoAxes, 3);
  const colmap::Rigid3d true_cam_from_lidar = sim::TrueCamFromLidar();
  const double baseline = rig.BaselineMeters();
  const double focal = rig.left.params[0];

  // Landmarks: visible surface points of the structure seen by at least two stations.
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0, 1);
  colmap::Reconstruction reconstruction;
  colmap::Camera camera = rig.left;
  camera.camera_id = 1;
  reconstruction.AddCamera(camera);
  std::vector<std::vector<Eigen::Vector2d>> points2D(truth.size());
  std::vector<std::vector<std::pair<size_t, size_t>>> tracks;  // (station, point2D index)
  const PointCloud surface = scene.SampleObjectSurface(0.04);
  std::vector<Eigen::Vector3d> landmarks;
  for (size_t p = 0; p < surface.Size(); p += 3) {
    const Eigen::Vector3d& point = surface.points[p];
    std::vector<std::pair<size_t, size_t>> track;
    for (size_t s = 0; s < truth.size(); ++s) {
      const Eigen::Vector3d in_cam = truth[s] * point;
      if (in_cam.z() < 0.5) continue;
      const Eigen::Vector2d xy = camera.ImgFromCam(in_cam.hnormalized());
      if (xy.x() < 1 || xy.y() < 1 || xy.x() > camera.width - 1 || xy.y() > camera.height - 1) {
        continue;
      }
      const Eigen::Vector3d center = colmap::Inverse(truth[s]).translation;
      sim::RayHit hit;
      const double distance = (point - center).norm();
      if (scene.Intersect(center, (point - center) / distance, distance + 1, &hit) &&
          hit.t < distance - 1e-3) {
        continue;  // occluded
      }
      track.emplace_back(s, points2D[s].size());
      points2D[s].push_back(xy);
    }
    if (track.size() >= 2) {
      tracks.push_back(track);
      landmarks.push_back(point);
    } else {
      for (const auto& [s, index] : track) points2D[s].pop_back();
    }
  }
  ASSERT_GT(landmarks.size(), 500u);

  JointProblemData data;
  for (size_t s = 0; s < truth.size(); ++s) {
    colmap::Image image;
    image.SetImageId(static_cast<colmap::image_t>(s + 1));
    image.SetName("left/" + std::to_string(s) + ".png");
    image.SetCameraId(1);
    image.SetPoints2D(points2D[s]);
    image.CamFromWorld() = s == 0 ? truth[s] : sim::PerturbPose(truth[s], 0.3, 0.01, 100 + s);
    reconstruction.AddImage(image);
    reconstruction.RegisterImage(image.ImageId());
  }
  for (size_t k = 0; k < landmarks.size(); ++k) {
    colmap::Track track;
    for (const auto& [s, index] : tracks[k]) {
      track.AddElement(static_cast<colmap::image_t>(s + 1), static_cast<colmap::point2D_t>(index));
      // The exact depth prior, weighted as the seed does.
      const double depth = (truth[s] * landmarks[k]).z();
      data.depth_priors[static_cast<colmap::image_t>(s + 1)][index] = {
          static_cast<colmap::point2D_t>(index), depth, DepthSigma(depth, baseline, focal, 1.0)};
    }
    const Eigen::Vector3d start =
        landmarks[k] + 0.01 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    reconstruction.AddPoint3D(start, track);
  }

  // Noise-free LiDAR scans of every station.
  std::vector<std::unique_ptr<StationCloud>> clouds;
  StationCloudOptions cloud_options;
  cloud_options.compute_features = false;
  for (size_t s = 0; s < truth.size(); ++s) {
    sim::LidarOptions lidar;
    lidar.num_points = 300000;
    lidar.range_noise_m = 0;
    lidar.seed = s;
    const PointCloud scan =
        sim::ScanLidar(scene, colmap::Inverse(truth[s]) * true_cam_from_lidar, lidar);
    clouds.push_back(PrepareStationCloud(scan, cloud_options));
    data.clouds[static_cast<colmap::image_t>(s + 1)] = clouds.back().get();
    for (size_t t = s + 1; t < truth.size(); ++t) {
      data.pairs.emplace_back(s + 1, t + 1);
    }
  }

  colmap::Rigid3d cam_from_lidar = sim::PerturbPose(true_cam_from_lidar, 5.0, 0.10, 42);
  JointAdjusterOptions options;
  options.association.num_samples = 1500;
  options.association.max_curvature = 0.01;
  JointAdjuster adjuster(options, data);
  const JointAdjustmentSummary summary = adjuster.Run(&reconstruction, &cam_from_lidar);
  ASSERT_FALSE(summary.solves.empty());

  const double rotation_error =
      RotationErrorDeg(cam_from_lidar.rotation, true_cam_from_lidar.rotation);
  const double translation_error_mm =
      1000 * (cam_from_lidar.translation - true_cam_from_lidar.translation).norm();
  double max_pose_error_mm = 0;
  for (size_t s = 0; s < truth.size(); ++s) {
    const colmap::Rigid3d& estimate =
        reconstruction.Image(static_cast<colmap::image_t>(s + 1)).CamFromWorld();
    max_pose_error_mm = std::max(
        max_pose_error_mm,
        1000 *
            (colmap::Inverse(estimate).translation - colmap::Inverse(truth[s]).translation).norm());
  }
  std::cout << "exact data: cam_from_lidar error " << rotation_error << " deg, "
            << translation_error_mm << " mm; station positions max " << max_pose_error_mm << " mm ("
            << landmarks.size() << " landmarks)" << std::endl;
  EXPECT_LT(rotation_error, 0.01);
  EXPECT_LT(translation_error_mm, 0.5);
  EXPECT_LT(max_pose_error_mm, 0.5);
  EXPECT_TRUE(summary.motion.unique) << summary.motion.verdict;
}

}  // namespace
}  // namespace colmap_lidar
