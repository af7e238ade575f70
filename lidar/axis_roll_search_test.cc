#include "lidar/axis_roll_search.h"

#include "tests/testing/camera_lidar_scene.h"
#include "tests/testing/car_cam_from_lidar.h"
#include "tests/testing/ray_cast_street.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <random>

namespace colmap_lidar {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

Eigen::Isometry3d TrueCamFromLidar() { return testing::CarCamFromLidar(0.03); }

// Five stations 3 m apart along a straight street (no turn at all): static LiDAR scans (1 cm noise)
// and camera points cast through a 90 x 30 deg field of view with a depth error of d^2 / 300 m
// along the ray (two-view triangulation over a short baseline).
using StraightStreet = testing::CameraLidarScene;

CameraDepthPoints CastCameraPoints(const std::vector<testing::Box>& boxes,
                                   const Eigen::Isometry3d& world_from_cam,
                                   std::mt19937* rng) {
  std::normal_distribution<double> gaussian(0, 1);
  CameraDepthPoints camera;
  for (double x = -1; x <= 1; x += 0.02) {
    for (double y = -0.27; y <= 0.27; y += 0.02) {
      const Eigen::Vector3d ray = Eigen::Vector3d(x, y, 1).normalized();
      const double range =
          testing::CastRay(boxes, world_from_cam.translation(), world_from_cam.linear() * ray);
      if (!(range < 30)) continue;
      const double sigma = range * range / 300;
      camera.point_in_cam.push_back((range + sigma * gaussian(*rng)) * ray);
      camera.sigma_along_ray_m.push_back(sigma);
    }
  }
  return camera;
}

// The street's boxes moved by -x: a scan from x = 0 (testing::ScanSweep at rest) sees the street
// as from x.
std::vector<testing::Box> Shifted(std::vector<testing::Box> boxes, double x) {
  for (testing::Box& box : boxes) {
    box.lo.x() -= x;
    box.hi.x() -= x;
  }
  return boxes;
}

StraightStreet MakeStraightStreet(uint32_t seed) {
  const std::vector<testing::Box> street_boxes = testing::StreetBoxes(seed, 40);
  std::mt19937 rng(seed);
  StationCloudOptions cloud_options;
  cloud_options.compute_features = false;
  const Eigen::Isometry3d world_from_lidar(Eigen::Translation3d(0, 0, 1.8));
  StraightStreet street;
  for (int i = 0; i < 5; ++i) {
    const std::vector<testing::Box> boxes = Shifted(street_boxes, 5 + 3 * i);
    PointCloud lidar;
    lidar.points = testing::ScanSweep(boxes, 0, 0, 0, 32, 900, 0.01, &rng);
    street.clouds.push_back(PrepareStationCloud(lidar, cloud_options));
    street.points.push_back(
        CastCameraPoints(boxes, world_from_lidar * TrueCamFromLidar().inverse(), &rng));
  }
  return street;
}

double RotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() * kRadToDeg;
}

// The start: the truth turned by `roll_deg` about the camera's z (the direction of travel), with
// the translation unknown (0).
Eigen::Isometry3d RolledStart(double roll_deg) {
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.linear() =
      Eigen::AngleAxisd(roll_deg / kRadToDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
      TrueCamFromLidar().linear();
  return start;
}

TEST(AxisRollSearchTest, FindsTheRollAboutTheTravelDirectionFromAnyStart) {
  const StraightStreet street = MakeStraightStreet(3);
  for (const double roll_deg : {0.0, 47.0, 133.0, -100.0}) {
    const AxisRollSearchResult search = SearchRollAboutAxis(
        street.points, street.Clouds(), RolledStart(roll_deg), Eigen::Vector3d::UnitZ(), {});
    const double error_deg = RotationErrorDeg(search.cam_from_lidar, TrueCamFromLidar());
    std::cout << "start roll " << roll_deg << " deg: error " << error_deg << " deg, rms "
              << search.best_rms_m << " m, runner-up " << search.runner_up_roll_deg << " deg at "
              << search.runner_up_rms_m << " m" << std::endl;
    EXPECT_LT(error_deg, 1.5);
    EXPECT_GT(search.runner_up_rms_m, 1.5 * search.best_rms_m);
    EXPECT_EQ(search.rms_by_roll.size(), 360u);
  }
}

TEST(AxisRollSearchTest, TheAlignmentFromTheBestRollRecoversTheExtrinsic) {
  const StraightStreet street = MakeStraightStreet(4);
  const AxisRollSearchResult search = SearchRollAboutAxis(
      street.points, street.Clouds(), RolledStart(75), Eigen::Vector3d::UnitZ(), {});
  const ExtrinsicAlignmentResult aligned =
      AlignCameraPointsWithLidar(street.points, street.Clouds(), search.cam_from_lidar, {});
  const double rotation_deg = RotationErrorDeg(aligned.cam_from_lidar, TrueCamFromLidar());
  const double translation_m =
      (aligned.cam_from_lidar.translation() - TrueCamFromLidar().translation()).norm();
  std::cout << "aligned: " << rotation_deg << " deg, " << 1000 * translation_m << " mm"
            << std::endl;
  EXPECT_LT(rotation_deg, 0.45);
  EXPECT_LT(translation_m, 0.07);
}

TEST(AxisRollSearchTest, BadInputIsRefused) {
  const StraightStreet street = MakeStraightStreet(5);
  EXPECT_THROW(SearchRollAboutAxis(street.points, {}, RolledStart(0), Eigen::Vector3d::UnitZ(), {}),
               std::invalid_argument);
  EXPECT_THROW(SearchRollAboutAxis(
                   street.points, street.Clouds(), RolledStart(0), Eigen::Vector3d::Zero(), {}),
               std::invalid_argument);
  AxisRollSearchOptions options;
  options.step_deg = 0;
  EXPECT_THROW(
      SearchRollAboutAxis(
          street.points, street.Clouds(), RolledStart(0), Eigen::Vector3d::UnitZ(), options),
      std::invalid_argument);
  std::vector<CameraDepthPoints> empty(street.points.size());
  EXPECT_THROW(
      SearchRollAboutAxis(empty, street.Clouds(), RolledStart(0), Eigen::Vector3d::UnitZ(), {}),
      std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
