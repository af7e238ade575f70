#include "colmap_ext/stereo_depth.h"

#include "colmap_ext/elapsed.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/stereo_depth_files.h"
#include "lidar/util/parallel_for_each.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

int OpenCvSgbmMode(SgbmMode mode) {
  switch (mode) {
    case SgbmMode::kSgbm:
      return cv::StereoSGBM::MODE_SGBM;
    case SgbmMode::kHh:
      return cv::StereoSGBM::MODE_HH;
    case SgbmMode::kSgbm3Way:
      return cv::StereoSGBM::MODE_SGBM_3WAY;
    case SgbmMode::kHh4:
      return cv::StereoSGBM::MODE_HH4;
  }
  return cv::StereoSGBM::MODE_SGBM;
}

// Disparity search range [min, min + num) from the depth range: num is a multiple of 16 (OpenCV).
void DisparityRange(const StereoRectifier& rectifier,
                    const StereoDepthOptions& options,
                    int* min_disparity,
                    int* num_disparities) {
  const double fb = rectifier.RectifiedFocalLength() * rectifier.BaselineMeters();
  *min_disparity = static_cast<int>(std::floor(fb / options.max_depth_m));
  const int max_disparity = static_cast<int>(std::ceil(fb / options.min_depth_m));
  *num_disparities = std::max(16, (max_disparity - *min_disparity + 15) / 16 * 16);
}

// CV_16S fixed-point (x16) SGBM output to float pixels; invalid -> 0.
cv::Mat ToPixels(const cv::Mat& fixed, int min_disparity) {
  cv::Mat disparity(fixed.size(), CV_32F, cv::Scalar(0));
  for (int row = 0; row < fixed.rows; ++row) {
    for (int col = 0; col < fixed.cols; ++col) {
      const short raw = fixed.at<short>(row, col);
      if (raw >= min_disparity * 16 && raw > 0) {
        disparity.at<float>(row, col) = raw / 16.f;
      }
    }
  }
  return disparity;
}

// SGBM (5 paths) aggregates its smoothness term along paths that all come from the rows above, so a
// surface slanted in y (the ground) gets the disparity of rows a fraction of a pixel higher, so its
// depth comes out too far in proportion to the inverse-depth gradient per row. Matching
// the vertically flipped pair as well aggregates from below; the mean of both cancels the shift, and
// pixels where the two passes disagree by more than max_diff_px are dropped. Fixed-point (x16) output.
cv::Mat ComputeVerticallySymmetric(cv::StereoSGBM& matcher,
                                   const cv::Mat& reference,
                                   const cv::Mat& other,
                                   double max_diff_px) {
  cv::Mat down, up_flipped, reference_flipped, other_flipped, up;
  matcher.compute(reference, other, down);
  cv::flip(reference, reference_flipped, 0);
  cv::flip(other, other_flipped, 0);
  matcher.compute(reference_flipped, other_flipped, up_flipped);
  cv::flip(up_flipped, up, 0);
  const short invalid = static_cast<short>((matcher.getMinDisparity() - 1) * 16);
  const int max_diff = static_cast<int>(std::lround(16 * max_diff_px));
  cv::Mat combined(down.size(), CV_16S);
  for (int row = 0; row < down.rows; ++row) {
    for (int col = 0; col < down.cols; ++col) {
      const short a = down.at<short>(row, col), b = up.at<short>(row, col);
      const bool valid = a > invalid && b > invalid && std::abs(a - b) <= max_diff;
      combined.at<short>(row, col) = valid ? static_cast<short>((a + b) / 2) : invalid;
    }
  }
  return combined;
}

// Left-right consistency: left disparities whose right match disagrees by more than max_diff_px, or
// that lie outside the original image (mask 0), are set to 0. Returns |d_left - d_right| per kept
// pixel, -1 elsewhere. Without a right disparity map (empty: SGBM checked already) only the mask
// applies and kept pixels get 0.
cv::Mat LeftRightCheck(const cv::Mat& right_disparity,
                       const cv::Mat& mask,
                       double max_diff_px,
                       cv::Mat* left_disparity) {
  cv::Mat lr_diff(left_disparity->size(), CV_32F, cv::Scalar(-1));
  for (int row = 0; row < left_disparity->rows; ++row) {
    for (int col = 0; col < left_disparity->cols; ++col) {
      float& d = left_disparity->at<float>(row, col);
      if (d <= 0.f) continue;
      float diff = 0.f, d_right = d;
      if (!right_disparity.empty()) {
        const int right_col = static_cast<int>(std::lround(col - d));
        d_right = right_col >= 0 ? right_disparity.at<float>(row, right_col) : 0.f;
        diff = std::abs(d - d_right);
      }
      if (mask.at<uchar>(row, col) == 0 || d_right <= 0.f || diff > max_diff_px) {
        d = 0.f;
      } else {
        lr_diff.at<float>(row, col) = diff;
      }
    }
  }
  return lr_diff;
}

// Confidence in the original grid: the left-right agreement of the nearest rectified pixel, at least
// 1 where there is depth and 0 where there is none.
cv::Mat Confidence(const StereoRectifier& rectifier,
                   const cv::Mat& lr_diff,
                   double max_diff_px,
                   const cv::Mat& depth) {
  cv::Mat confidence_rectified(lr_diff.size(), CV_8U, cv::Scalar(0));
  for (int row = 0; row < lr_diff.rows; ++row) {
    for (int col = 0; col < lr_diff.cols; ++col) {
      const float diff = lr_diff.at<float>(row, col);
      if (diff < 0.f) continue;
      confidence_rectified.at<uchar>(row, col) =
          static_cast<uchar>(std::lround(1 + 254 * (1.0 - diff / (max_diff_px + 1e-9))));
    }
  }
  cv::Mat confidence = rectifier.ToLeftImage(confidence_rectified);
  for (int row = 0; row < depth.rows; ++row) {
    for (int col = 0; col < depth.cols; ++col) {
      uchar& c = confidence.at<uchar>(row, col);
      c = depth.at<float>(row, col) > 0.f ? std::max<uchar>(1, c) : 0;
    }
  }
  return confidence;
}

cv::Mat ReadImageOrThrow(const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) {
    throw std::runtime_error("cannot read image " + path);
  }
  return image;
}

// OpenCV's semi-global matcher with the options' penalties and checks.
cv::Ptr<cv::StereoSGBM> MakeSgbm(int min_disparity,
                                 int num_disparities,
                                 const StereoDepthOptions& options) {
  const int area = options.block_size * options.block_size;
  return cv::StereoSGBM::create(
      min_disparity,
      num_disparities,
      options.block_size,
      options.p1_factor * area,
      options.p2_factor * area,
      /*disp12MaxDiff=*/options.mirrored_left_right_check
          ? -1
          : std::max(1, static_cast<int>(std::lround(options.max_left_right_diff_px))),
      options.pre_filter_cap,
      options.uniqueness_ratio,
      options.speckle_window_size,
      static_cast<int>(std::ceil(options.speckle_range_px)),
      OpenCvSgbmMode(options.mode));
}

void PrintStereoSetup(const StationDataset& dataset,
                      const StereoRectifier& rectifier,
                      int min_disparity,
                      int num_disparities,
                      const StereoDepthOptions& options) {
  std::cout << "Stereo depth: " << dataset.stations.size() << " stations, "
            << rectifier.ImageSize().width << "x" << rectifier.ImageSize().height
            << ", rectified f " << std::fixed << std::setprecision(1)
            << rectifier.RectifiedFocalLength() << " px, baseline " << std::setprecision(3)
            << rectifier.BaselineMeters() << " m, disparities " << min_disparity << ".."
            << min_disparity + num_disparities - 1 << " px, SGBM mode "
            << ChoiceName(kSgbmModeNames, options.mode) << std::endl;
}

}  // namespace

bool StereoDepthOptions::Check() const {
  CHECK_OPTION_GT(min_depth_m, 0);
  CHECK_OPTION_GT(max_depth_m, min_depth_m);
  CHECK_OPTION_GE(block_size, 1);
  CHECK_OPTION_EQ(block_size % 2, 1);
  CHECK_OPTION_GT(p2_factor, p1_factor);
  CHECK_OPTION_GE(uniqueness_ratio, 0);
  CHECK_OPTION_GE(speckle_window_size, 0);
  CHECK_OPTION_GE(speckle_range_px, 0);
  CHECK_OPTION_GT(max_left_right_diff_px, 0);
  return true;
}

StereoDepth ComputeStereoDepth(const cv::Mat& left_image,
                               const cv::Mat& right_image,
                               const StereoRectifier& rectifier,
                               const StereoDepthOptions& options) {
  if (left_image.size() != rectifier.ImageSize() || right_image.size() != rectifier.ImageSize()) {
    std::ostringstream message;
    message << "stereo pair sizes (left " << left_image.cols << "x" << left_image.rows << ", right "
            << right_image.cols << "x" << right_image.rows << ") differ from the rig's "
            << rectifier.ImageSize().width << "x" << rectifier.ImageSize().height;
    throw std::invalid_argument(message.str());
  }
  cv::Mat left_grey = left_image, right_grey = right_image;
  if (left_grey.channels() == 3) cv::cvtColor(left_image, left_grey, cv::COLOR_BGR2GRAY);
  if (right_grey.channels() == 3) cv::cvtColor(right_image, right_grey, cv::COLOR_BGR2GRAY);
  cv::Mat left_rectified, right_rectified;
  rectifier.Rectify(left_grey, right_grey, &left_rectified, &right_rectified);

  int min_disparity = 0, num_disparities = 0;
  DisparityRange(rectifier, options, &min_disparity, &num_disparities);
  const cv::Ptr<cv::StereoSGBM> matcher = MakeSgbm(min_disparity, num_disparities, options);

  // Left disparity (and, for the mirrored check, the right image's disparity by matching the mirrored
  // pair, the right image as the reference: d_right(x) = d such that right x matches left x + d).
  // SGBM leaves the first min + num disparity columns invalid; padding the pair on the side of the
  // reference image's border keeps every pixel whose match lies inside the other image.
  const int pad = min_disparity + num_disparities;
  const auto match = [&](const cv::Mat& reference, const cv::Mat& other) {
    cv::Mat reference_padded, other_padded, fixed;
    cv::copyMakeBorder(reference, reference_padded, 0, 0, pad, 0, cv::BORDER_CONSTANT, 0);
    cv::copyMakeBorder(other, other_padded, 0, 0, pad, 0, cv::BORDER_CONSTANT, 0);
    if (options.vertically_symmetric) {
      fixed = ComputeVerticallySymmetric(
          *matcher, reference_padded, other_padded, options.max_left_right_diff_px);
    } else {
      matcher->compute(reference_padded, other_padded, fixed);
    }
    return fixed(cv::Rect(pad, 0, reference.cols, reference.rows)).clone();
  };
  cv::Mat left_disparity = ToPixels(match(left_rectified, right_rectified), min_disparity);
  cv::Mat right_disparity;
  if (options.mirrored_left_right_check) {
    cv::Mat left_mirrored, right_mirrored, right_fixed;
    cv::flip(left_rectified, left_mirrored, 1);
    cv::flip(right_rectified, right_mirrored, 1);
    cv::flip(match(right_mirrored, left_mirrored), right_fixed, 1);
    right_disparity = ToPixels(right_fixed, min_disparity);
  }
  const cv::Mat lr_diff = LeftRightCheck(right_disparity,
                                         rectifier.LeftRectifiedMask(),
                                         options.max_left_right_diff_px,
                                         &left_disparity);
  StereoDepth result;
  result.depth = rectifier.DepthInLeftImage(left_disparity);
  result.confidence = Confidence(rectifier, lr_diff, options.max_left_right_diff_px, result.depth);
  const size_t num_valid = static_cast<size_t>(cv::countNonZero(result.depth > 0.f));
  result.valid_fraction =
      static_cast<double>(num_valid) / static_cast<double>(result.depth.total());
  return result;
}

void ComputeDatasetStereoDepth(const StationDataset& dataset,
                               const std::string& output_path,
                               const StereoDepthOptions& options) {
  THROW_CHECK(options.Check());
  if (!dataset.rig.IsStereo()) {
    throw std::runtime_error(dataset.root +
                             "/rig.json describes a monocular rig (no 'right' camera): there is no "
                             "stereo depth to compute");
  }
  const StereoRectifier rectifier(
      dataset.rig.left, *dataset.rig.right, dataset.rig.right_from_left);
  int min_disparity = 0, num_disparities = 0;
  DisparityRange(rectifier, options, &min_disparity, &num_disparities);
  PrintStereoSetup(dataset, rectifier, min_disparity, num_disparities, options);
  fs::create_directories(output_path);
  fs::remove(fs::path(output_path) / "stereo.json");  // not complete until rewritten

  const int num_stations = static_cast<int>(dataset.stations.size());
  std::vector<double> valid_fraction(dataset.stations.size(), 0);
  std::atomic<int> num_done{0};
  std::mutex print_mutex;
  const auto start = std::chrono::steady_clock::now();
  // One station per thread. OpenCV's own parallel loops (remap, some SGBM modes) run in the calling
  // thread while its pool is busy, so the stations do not oversubscribe the cores; the process's
  // OpenCV thread setting is left alone.
  ParallelForEach(
      num_stations,
      [&](int i) {
        const std::string& station = dataset.stations[i];
        try {
          const cv::Mat left = ReadImageOrThrow(dataset.LeftImagePath(i));
          const cv::Mat right = ReadImageOrThrow(dataset.RightImagePath(i));
          const StereoDepth depth = ComputeStereoDepth(left, right, rectifier, options);
          WriteStationStereoDepth(output_path, station, depth);
          valid_fraction[i] = depth.valid_fraction;
          const int done = ++num_done;
          const double seconds = SecondsSince(start);
          std::lock_guard<std::mutex> lock(print_mutex);
          std::cout << "  [" << done << "/" << num_stations << "] station " << station << ": "
                    << std::setprecision(1) << 100 * depth.valid_fraction
                    << " % of pixels with depth (" << std::setprecision(0) << seconds << " s)"
                    << std::endl;
        } catch (const std::exception& error) {
          throw std::runtime_error("station " + station + ": " + error.what());
        }
      },
      options.num_threads);

  StereoDepthInfo info;
  info.rectified_focal_px = rectifier.RectifiedFocalLength();
  info.baseline_m = rectifier.BaselineMeters();
  info.min_disparity_px = min_disparity;
  info.num_disparities = num_disparities;
  for (size_t i = 0; i < dataset.stations.size(); ++i) {
    info.valid_fraction[dataset.stations[i]] = valid_fraction[i];
  }
  WriteStereoDepthInfo(output_path, info, options);
}

}  // namespace colmap_lidar
