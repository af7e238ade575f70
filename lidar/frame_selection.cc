#include "lidar/frame_selection.h"

#include "lidar/util/check_option.h"

#include <cmath>

namespace colmap_lidar {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

// The greedy walk with both spacings multiplied by `factor`.
FrameSelection SelectWithFactor(const std::vector<Eigen::Isometry3d>& world_from_frame,
                                const FrameSelectionOptions& options,
                                double factor) {
  FrameSelection selection;
  selection.spacing_factor = factor;
  const int n = static_cast<int>(world_from_frame.size());
  selection.reasons.assign(n, FrameSelectionReason::kLeftOut);
  if (n == 0) return selection;
  selection.kept.push_back(0);
  selection.reasons[0] = FrameSelectionReason::kFirst;
  const bool keep_all = options.min_distance_m == 0 && options.min_rotation_deg == 0;
  for (int i = 1; i < n; ++i) {
    const Eigen::Isometry3d last_from_frame =
        world_from_frame[selection.kept.back()].inverse() * world_from_frame[i];
    const double distance_m = last_from_frame.translation().norm();
    const double rotation_deg = Eigen::AngleAxisd(last_from_frame.linear()).angle() * kDegPerRad;
    if (keep_all || (options.min_distance_m > 0 && distance_m >= factor * options.min_distance_m)) {
      selection.reasons[i] = FrameSelectionReason::kDistance;
    } else if (options.min_rotation_deg > 0 && rotation_deg >= factor * options.min_rotation_deg) {
      selection.reasons[i] = FrameSelectionReason::kRotation;
    } else if (i == n - 1) {
      selection.reasons[i] = FrameSelectionReason::kLast;
    } else {
      continue;
    }
    selection.kept.push_back(i);
  }
  return selection;
}

}  // namespace

bool FrameSelectionOptions::Check() const {
  LIDAR_CHECK_OPTION_GE(min_distance_m, 0);
  LIDAR_CHECK_OPTION_GE(min_rotation_deg, 0);
  LIDAR_CHECK_OPTION_GE(max_frames, 0);
  LIDAR_CHECK_OPTION(max_frames == 0 || max_frames >= 2);
  // Without a spacing every frame is kept, and there is no spacing to grow for a cap.
  LIDAR_CHECK_OPTION(max_frames == 0 || min_distance_m > 0 || min_rotation_deg > 0);
  return true;
}

std::string FrameSelectionReasonName(FrameSelectionReason reason) {
  switch (reason) {
    case FrameSelectionReason::kFirst:
      return "first";
    case FrameSelectionReason::kDistance:
      return "distance";
    case FrameSelectionReason::kRotation:
      return "rotation";
    case FrameSelectionReason::kLast:
      return "last";
    case FrameSelectionReason::kLeftOut:
      return "left out";
  }
  return "";
}

FrameSelection SelectFrames(const std::vector<Eigen::Isometry3d>& world_from_frame,
                            const FrameSelectionOptions& options) {
  ThrowUnlessValid(options, "FrameSelectionOptions");
  FrameSelection selection = SelectWithFactor(world_from_frame, options, 1);
  const size_t max_frames = static_cast<size_t>(options.max_frames);
  if (max_frames == 0 || selection.kept.size() <= max_frames) return selection;
  // The count falls as the factor grows (up to the greedy walk's jitter): double the factor until
  // the cap holds, then bisect between the last factor over and the first within the cap.
  double low = 1, high = 2;
  // A factor that spaces the kept frames beyond the whole path keeps only the first and the last.
  while (SelectWithFactor(world_from_frame, options, high).kept.size() > max_frames) {
    low = high;
    high *= 2;
  }
  for (int iteration = 0; iteration < 30 && high - low > 1e-3 * low; ++iteration) {
    const double middle = 0.5 * (low + high);
    if (SelectWithFactor(world_from_frame, options, middle).kept.size() > max_frames) {
      low = middle;
    } else {
      high = middle;
    }
  }
  return SelectWithFactor(world_from_frame, options, high);
}

}  // namespace colmap_lidar
