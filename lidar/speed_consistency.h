// Constant-velocity check of the LiDAR pose graph's edges between sweeps of a moving platform. A car's
// speed changes little from one sweep to the next, so the speed an edge implies, |t| over the frames it
// spans, must agree with the median speed of the edges around it. Along a street, ICP between two
// sweeps can slide to (nearly) no motion: the facades fit at any offset along the street and a car
// driving ahead at our speed fits best at none. Such an edge closes its 3-cycles when its neighbours
// slid too, so the cycle check (lidar/cycle_consistency.h) cannot see it; its speed gives it away.
// The check predicts where the edge should be (the neighbours' velocity), and the pose graph
// (lidar/lidar_pose_graph.h) registers it again from there, as KISS-ICP's constant-velocity model
// starts each sweep's ICP.
#pragma once

#include "lidar/cycle_consistency.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace colmap_lidar {

struct SpeedConsistencyOptions {
  // Edges spanning at most this many frames carry the neighbours' speed. An edge's neighbours are
  // those whose middle frame lies within this many frames of its own.
  double window_frames = 5;
  // Edges spanning at most this many frames are judged (a loop closure, revisiting a place much
  // later, is not).
  double max_judged_span_frames = 20;
  // An edge contradicts its neighbours when its speed differs from their median by more than this
  // fraction of the median and by more than min_deviation_m_per_frame (a walking pace never does).
  double max_relative_deviation = 0.5;
  double min_deviation_m_per_frame = 0.2;
  // An edge with fewer neighbours (itself included when it spans at most window_frames) is not
  // judged.
  int min_neighbours = 4;

  bool Check() const;
};

struct SpeedCheck {
  std::vector<bool> removed;        // per edge
  std::vector<std::string> reason;  // per edge: why it was removed (empty if kept)
  // Per removed edge: its target_from_source translation under the neighbours' velocity (the
  // component-wise median of their translations per frame, signed by the frame order), where ICP
  // can start again.
  std::vector<Eigen::Vector3d> predicted_translation;
};

// Whether a speed agrees with its neighbours' median within the tolerances of `options`.
bool SpeedAgrees(double m_per_frame,
                 double median_m_per_frame,
                 const SpeedConsistencyOptions& options);

// `frame_indices`: each station's frame (time order, in frame periods), indexed like the edges'
// target and source.
SpeedCheck CheckSpeedConsistency(const std::vector<RelativePose>& edges,
                                 const std::vector<double>& frame_indices,
                                 const SpeedConsistencyOptions& options);

}  // namespace colmap_lidar
