#include "colmap_ext/image_line_segments.h"

#include "tests/testing/scoped_temp_dir.h"
#include "tests/testing/vertical_faces.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <fstream>

namespace colmap_lidar {
namespace {

constexpr double kDeg = M_PI / 180.0;

colmap::Camera TestCamera() {
  return colmap::Camera::CreateFromModelName(1, "PINHOLE", 700, 1000, 600);
}

// A camera 1.5 m above the ground looking along world +x, rolled by `roll_deg` about its optical axis.
colmap::Rigid3d RolledCamFromWorld(double roll_deg) {
  Eigen::Matrix3d cam_from_world_upright;
  cam_from_world_upright << 0, -1, 0, 0, 0, -1, 1, 0, 0;  // x right, y down, z forward
  const Eigen::Quaterniond rotation = Eigen::AngleAxisd(roll_deg * kDeg, Eigen::Vector3d::UnitZ()) *
                                      Eigen::Quaterniond(cam_from_world_upright);
  return colmap::Rigid3d(rotation, -(rotation * Eigen::Vector3d(0, 0, 1.5)));
}

TEST(ImageLineSegmentsTest, VerticalEdgesGivePlanesContainingTheVertical) {
  const colmap::Camera camera = TestCamera();
  const colmap::Rigid3d cam_from_world = RolledCamFromWorld(3.0);
  const std::vector<testing::VerticalFace> faces = {
      {{8, 3}, {12, 3}, 4}, {{6, -2.5}, {9, -3}, 3}, {{15, 1}, {15, -1}, 2.5}};
  const cv::Mat image = testing::RenderVerticalFaces(camera, cam_from_world, faces, 4.0, 1);
  const Eigen::Vector3d up_in_cam = cam_from_world.rotation * Eigen::Vector3d::UnitZ();
  int num_vertical = 0;
  double largest_deg = 0;
  for (const LineSegment& segment : DetectLineSegments(image, LineSegmentOptions())) {
    const double angle_deg =
        std::asin(std::abs(InterpretationPlaneNormal(camera, segment).dot(up_in_cam))) / kDeg;
    if (angle_deg > 5) continue;  // horizontal edges of the faces
    ++num_vertical;
    largest_deg = std::max(largest_deg, angle_deg);
  }
  std::cout << num_vertical << " vertical segments, largest angle to the vertical " << largest_deg
            << " deg" << std::endl;
  // 3 faces, 6 vertical edges (some split by the noise); measured: largest 0.06 deg.
  EXPECT_GE(num_vertical, 5);
  EXPECT_LT(largest_deg, 0.2);
}

TEST(ImageLineSegmentsTest, CoordinatesFollowColmapsPixelCentres) {
  // A bright half-plane right of column 400 (pixels 0..399 dark): the edge lies at x = 400 in
  // COLMAP's convention (the boundary between pixel centres 399.5 and 400.5).
  cv::Mat image(300, 800, CV_8UC1, cv::Scalar(40));
  image(cv::Rect(400, 0, 400, 300)).setTo(220);
  LineSegmentOptions options;
  options.blur_sigma_px = 0;
  const std::vector<LineSegment> segments = DetectLineSegments(image, options);
  ASSERT_FALSE(segments.empty());
  EXPECT_NEAR(segments.front().start.x(), 400, 0.3);
  EXPECT_NEAR(segments.front().end.x(), 400, 0.3);
  EXPECT_GT(segments.front().Length(), 250);
}

TEST(ImageLineSegmentsTest, AnUnreadableImageIsNamed) {
  testing::ScopedTempDir dir;
  std::ofstream(dir.File("broken.png")) << "not a png";
  try {
    DetectLineSegments(dir.File("broken.png"), LineSegmentOptions());
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(dir.File("broken.png")), std::string::npos);
  }
}

}  // namespace
}  // namespace colmap_lidar
