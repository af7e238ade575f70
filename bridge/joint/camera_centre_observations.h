// Observations whose landmark sits at the observing camera's centre. A landmark near the focus of
// expansion of a forward-moving camera has a depth its rays barely determine; the adjustment can
// slide it along the direction of travel until it lies at a later camera's centre. There its
// projection is undefined, the observation's derivatives grow as 1 / depth, and it alone decides
// that camera's pose: the normal matrix becomes singular (a failed solve naming the pose) or the
// reported sigmas collapse. COLMAP's checks do not catch it: its reprojection error is small, its
// depth positive, and its triangulation angle numerically arbitrary.
#pragma once

#include "colmap/scene/reconstruction.h"

#include <utility>
#include <vector>

namespace colmap_lidar {

// A landmark's depth in an observing camera below this fraction of the median depth of all
// observations: millimetres from the lens on a street, nearer than any lens focuses and far below
// any landmark a camera can observe.
inline constexpr double kMinRelativeLandmarkDepth = 1e-4;

// (image, point2D) of every observation whose landmark's depth in that image's camera is below
// `min_relative_depth` times the median depth of all landmark observations of `reconstruction`.
std::vector<std::pair<colmap::image_t, colmap::point2D_t>> ObservationsAtCameraCentres(
    const colmap::Reconstruction& reconstruction,
    double min_relative_depth = kMinRelativeLandmarkDepth);

}  // namespace colmap_lidar
