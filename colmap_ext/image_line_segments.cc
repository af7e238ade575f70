#include "colmap_ext/image_line_segments.h"

#include "colmap_ext/edge_distance_transform.h"
#include "colmap_ext/logging.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <stdexcept>

namespace colmap_lidar {

bool LineSegmentOptions::Check() const {
  CHECK_OPTION_GT(min_length_px, 0);
  CHECK_OPTION_GE(max_image_size, 64);
  CHECK_OPTION_GE(blur_sigma_px, 0);
  return true;
}

std::vector<LineSegment> DetectLineSegments(const cv::Mat& image,
                                            const LineSegmentOptions& options) {
  THROW_CHECK(options.Check());
  cv::Mat grey = GreyImage(image);
  const double scale =
      std::min(1.0, double(options.max_image_size) / std::max(grey.cols, grey.rows));
  if (scale < 1.0) cv::resize(grey, grey, cv::Size(), scale, scale, cv::INTER_AREA);
  if (options.blur_sigma_px > 0) cv::GaussianBlur(grey, grey, cv::Size(), options.blur_sigma_px);
  std::vector<cv::Vec4f> lines;
  cv::createLineSegmentDetector(cv::LSD_REFINE_STD)->detect(grey, lines);
  std::vector<LineSegment> segments;
  for (const cv::Vec4f& line : lines) {
    // OpenCV puts pixel centres at integers, COLMAP at +0.5; undo the scaling about the corner.
    LineSegment segment;
    segment.start = (Eigen::Vector2d(line[0], line[1]) + Eigen::Vector2d::Constant(0.5)) / scale;
    segment.end = (Eigen::Vector2d(line[2], line[3]) + Eigen::Vector2d::Constant(0.5)) / scale;
    if (segment.Length() >= options.min_length_px) segments.push_back(segment);
  }
  std::sort(segments.begin(), segments.end(), [](const LineSegment& a, const LineSegment& b) {
    return a.Length() > b.Length();
  });
  return segments;
}

std::vector<LineSegment> DetectLineSegments(const std::string& image_path,
                                            const LineSegmentOptions& options) {
  const cv::Mat image = cv::imread(image_path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) {
    throw std::runtime_error("Cannot read the image " + image_path + " (missing or not an image)");
  }
  return DetectLineSegments(image, options);
}

Eigen::Vector3d InterpretationPlaneNormal(const colmap::Camera& camera,
                                          const LineSegment& segment) {
  const Eigen::Vector3d ray_start = camera.CamFromImg(segment.start).homogeneous();
  const Eigen::Vector3d ray_end = camera.CamFromImg(segment.end).homogeneous();
  return ray_start.cross(ray_end).normalized();
}

}  // namespace colmap_lidar
