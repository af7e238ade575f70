#include "bridge/baselines/edge_axis_profile.h"

#include "colmap_ext/edge_distance_transform.h"

#include <colmap/sensor/models.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>

namespace colmap_lidar {
namespace {

const colmap::Rigid3d kCamFromLidar(
    Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * M_PI, Eigen::Vector3d(-1, 1, -1).normalized())),
    Eigen::Vector3d(0.19, -0.25, -0.05));

// A station whose image holds six grey rectangles at random places and whose LiDAR discontinuities
// are 400 points on their borders (depth 5-15 m), each placed `jitter_px` (Gaussian) off in the
// image before it is lifted into the LiDAR frame through kCamFromLidar.
EdgeStation RectangleStation(std::mt19937_64* random, double jitter_px) {
  EdgeStation station;
  station.camera =
      colmap::Camera::CreateFromModelId(1, colmap::PinholeCameraModel::model_id, 500, 640, 480);
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(60));
  std::uniform_int_distribution<int> col(20, 520), row(20, 360), size(40, 100), grey(120, 250);
  std::vector<cv::Rect> rectangles;
  for (int k = 0; k < 6; ++k) {
    rectangles.emplace_back(col(*random), row(*random), size(*random), size(*random));
    cv::rectangle(image, rectangles.back(), cv::Scalar(grey(*random)), cv::FILLED);
  }
  station.transform = InverseDistanceTransform(EdgeImage(image), EdgeDistanceTransformOptions());
  std::uniform_real_distribution<double> along(0, 1), depth(5, 15);
  std::normal_distribution<double> jitter(0, jitter_px);
  const colmap::Rigid3d lidar_from_cam = colmap::Inverse(kCamFromLidar);
  // The last rectangle drawn is wholly visible; its borders lie at continuous pixel coordinates.
  const cv::Rect& r = rectangles.back();
  for (int k = 0; k < 400; ++k) {
    const double t = along(*random);
    Eigen::Vector2d xy;
    switch (k % 4) {
      case 0:
        xy = {r.x, r.y + t * r.height};
        break;
      case 1:
        xy = {r.x + r.width, r.y + t * r.height};
        break;
      case 2:
        xy = {r.x + t * r.width, r.y};
        break;
      default:
        xy = {r.x + t * r.width, r.y + r.height};
    }
    xy += Eigen::Vector2d(jitter(*random), jitter(*random));
    const Eigen::Vector3d point_in_cam =
        depth(*random) * station.camera.CamFromImg(xy).homogeneous().eval();
    station.discontinuities.push_back({lidar_from_cam * point_in_cam, 1.0});
  }
  return station;
}

// Started 0.2 deg off about the optical axis, the profile peaks 0.2 deg back; its bootstrap sigma
// covers the error over seeded draws of 20 stations (the share within 2 sigma, ~95 % for an honest
// sigma, must be at least 0.8; with 8 stations the bootstrap gave 25 of 30, errors 1.4 sigma rms).
TEST(EdgeAxisProfile, FindsATurnAboutOneAxisWithAnHonestSigma) {
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  const colmap::Rigid3d start = TurnAboutCameraAxis(kCamFromLidar, axis, 0.2);
  EdgeAxisProfileOptions options;
  options.num_bootstrap = 200;
  int covered = 0;
  const int kDraws = 30;
  double largest_error = 0, sum_sigma = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    std::mt19937_64 random(draw);
    std::vector<EdgeStation> stations;
    for (int s = 0; s < 20; ++s) stations.push_back(RectangleStation(&random, 0.7));
    const EdgeAxisProfile profile = ProfileEdgeObjective(stations, start, axis, options);
    ASSERT_FALSE(profile.at_range_end);
    ASSERT_EQ(profile.angles_deg.size(), 121u);
    const double error = profile.peak_deg + 0.2;
    largest_error = std::max(largest_error, std::abs(error));
    sum_sigma += profile.sigma_deg;
    covered += std::abs(error) <= 2 * profile.sigma_deg;
  }
  std::cout << "edge profile: largest error " << largest_error << " deg, mean sigma "
            << sum_sigma / kDraws << " deg, " << covered << "/" << kDraws << " within 2 sigma"
            << std::endl;
  // Measured: largest error 0.031 deg, mean sigma 0.016 deg, 28 of 30 within 2 sigma (20 stations).
  EXPECT_LT(largest_error, 0.1);
  EXPECT_LT(sum_sigma / kDraws, 0.05);
  EXPECT_GE(covered, 0.8 * kDraws);
}

TEST(EdgeAxisProfile, SaysWhenThePeakLiesBeyondTheRange) {
  std::mt19937_64 random(7);
  const std::vector<EdgeStation> stations = {RectangleStation(&random, 0.0)};
  EdgeAxisProfileOptions options;
  options.half_range_deg = 0.1;
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  const EdgeAxisProfile profile =
      ProfileEdgeObjective(stations, TurnAboutCameraAxis(kCamFromLidar, axis, 0.4), axis, options);
  EXPECT_TRUE(profile.at_range_end);
  EXPECT_NEAR(profile.peak_deg, -0.1, 1e-12);
  options.step_deg = 0.2;
  EXPECT_THROW(ProfileEdgeObjective(stations, kCamFromLidar, axis, options), std::exception);
}

}  // namespace
}  // namespace colmap_lidar
