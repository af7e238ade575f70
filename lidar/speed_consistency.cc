#include "lidar/speed_consistency.h"

#include "lidar/util/check_option.h"
#include "lidar/util/statistics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {

bool SpeedConsistencyOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(window_frames, 0);
  LIDAR_CHECK_OPTION_GE(max_judged_span_frames, window_frames);
  LIDAR_CHECK_OPTION_GT(max_relative_deviation, 0);
  LIDAR_CHECK_OPTION_GE(min_deviation_m_per_frame, 0);
  LIDAR_CHECK_OPTION_GE(min_neighbours, 1);
  return true;
}

namespace {

struct EdgeSpeed {
  size_t edge = 0;
  double middle_frame = 0;
  double span = 0;  // frames
  double m_per_frame = 0;
  Eigen::Vector3d velocity;  // target_from_source translation per frame, source after target
};

}  // namespace

bool SpeedAgrees(double m_per_frame,
                 double median_m_per_frame,
                 const SpeedConsistencyOptions& options) {
  const double deviation = std::abs(m_per_frame - median_m_per_frame);
  return deviation <= options.max_relative_deviation * median_m_per_frame ||
         deviation <= options.min_deviation_m_per_frame;
}

SpeedCheck CheckSpeedConsistency(const std::vector<RelativePose>& edges,
                                 const std::vector<double>& frame_indices,
                                 const SpeedConsistencyOptions& options) {
  ThrowUnlessValid(options, "SpeedConsistencyOptions");
  std::vector<EdgeSpeed> speeds;
  for (size_t e = 0; e < edges.size(); ++e) {
    if (std::max(edges[e].target, edges[e].source) >= frame_indices.size()) {
      throw std::invalid_argument("CheckSpeedConsistency: an edge's station has no frame index");
    }
    const double frame_i = frame_indices[edges[e].target], frame_j = frame_indices[edges[e].source];
    const double span = std::abs(frame_j - frame_i);
    if (span == 0 || span > options.max_judged_span_frames) continue;
    const Eigen::Vector3d& t = edges[e].target_from_source.translation();
    speeds.push_back(
        {e, 0.5 * (frame_i + frame_j), span, t.norm() / span, t / (frame_j - frame_i)});
  }
  SpeedCheck check{std::vector<bool>(edges.size(), false),
                   std::vector<std::string>(edges.size()),
                   std::vector<Eigen::Vector3d>(edges.size(), Eigen::Vector3d::Zero())};
  for (const EdgeSpeed& edge : speeds) {
    std::vector<double> around;
    std::array<std::vector<double>, 3> velocity;
    for (const EdgeSpeed& other : speeds) {
      if (other.span > options.window_frames ||
          std::abs(other.middle_frame - edge.middle_frame) > options.window_frames) {
        continue;
      }
      around.push_back(other.m_per_frame);
      for (int axis = 0; axis < 3; ++axis) velocity[axis].push_back(other.velocity(axis));
    }
    if (static_cast<int>(around.size()) < options.min_neighbours) continue;
    const double median = Median(around);
    if (SpeedAgrees(edge.m_per_frame, median, options)) continue;
    const RelativePose& pose = edges[edge.edge];
    const double signed_span = frame_indices[pose.source] - frame_indices[pose.target];
    for (int axis = 0; axis < 3; ++axis) {
      check.predicted_translation[edge.edge](axis) = Median(velocity[axis]) * signed_span;
    }
    std::ostringstream reason;
    reason << "inconsistent speed: " << edge.m_per_frame << " m per frame where the "
           << around.size() << " edges around it say " << median
           << " (ICP slid along the way, or a moving object)";
    check.removed[edge.edge] = true;
    check.reason[edge.edge] = reason.str();
  }
  return check;
}

}  // namespace colmap_lidar
