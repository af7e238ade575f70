// Test scenes of plumb structure (tests only): vertical rectangles, each a wall or the side of a box,
// rendered into an image as bright faces on a noisy background, so that their vertical edges are the
// image's straight segments.
#pragma once

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"

#include <Eigen/Core>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace colmap_lidar {
namespace testing {

// A vertical rectangle in a world whose z axis is up: from `start` to `end` on the ground (z = 0
// at both), `height` tall.
struct VerticalFace {
  Eigen::Vector2d start;
  Eigen::Vector2d end;
  double height = 3;
};

// Renders the faces (painter's order: farthest first, greys 120-239) through `camera`; faces with a
// corner behind the camera are skipped. Background grey 60; Gaussian noise of `noise_grey` sigma.
inline cv::Mat RenderVerticalFaces(const colmap::Camera& camera,
                                   const colmap::Rigid3d& cam_from_world,
                                   const std::vector<VerticalFace>& faces,
                                   double noise_grey,
                                   unsigned seed) {
  cv::Mat image(
      static_cast<int>(camera.height), static_cast<int>(camera.width), CV_8UC1, cv::Scalar(60));
  std::vector<std::pair<double, std::vector<cv::Point>>> polygons;
  for (const VerticalFace& face : faces) {
    const Eigen::Vector3d corners[4] = {{face.start.x(), face.start.y(), 0},
                                        {face.end.x(), face.end.y(), 0},
                                        {face.end.x(), face.end.y(), face.height},
                                        {face.start.x(), face.start.y(), face.height}};
    std::vector<cv::Point> polygon;
    double depth = 0;
    for (const Eigen::Vector3d& corner : corners) {
      const Eigen::Vector3d point_in_cam = cam_from_world * corner;
      if (point_in_cam.z() < 0.5) break;
      depth += point_in_cam.z();
      // COLMAP's pixel centres at +0.5, OpenCV's at integers; 4 bits of sub-pixel precision.
      const Eigen::Vector2d xy = camera.ImgFromCam(point_in_cam.hnormalized());
      polygon.emplace_back(static_cast<int>(std::lround((xy.x() - 0.5) * 16)),
                           static_cast<int>(std::lround((xy.y() - 0.5) * 16)));
    }
    if (polygon.size() == 4) polygons.emplace_back(depth, polygon);
  }
  std::sort(polygons.begin(), polygons.end(), [](const auto& a, const auto& b) {
    return a.first > b.first;
  });
  for (size_t k = 0; k < polygons.size(); ++k) {
    const int grey = 120 + static_cast<int>(k * 37 % 120);
    cv::fillConvexPoly(image, polygons[k].second, cv::Scalar(grey), cv::LINE_AA, 4);
  }
  cv::Mat noisy, noise(image.size(), CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0, noise_grey);
  image.convertTo(noisy, CV_32FC1);
  noisy += noise;
  noisy.convertTo(image, CV_8UC1);  // saturating
  return image;
}

}  // namespace testing
}  // namespace colmap_lidar
