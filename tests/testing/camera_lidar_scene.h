// Stations of a synthetic scene for the camera-LiDAR alignment tests: each station's prepared LiDAR
// cloud and its camera-frame points. Header-only.
#pragma once

#include "lidar/extrinsic_alignment.h"
#include "lidar/station_cloud.h"

#include <memory>
#include <vector>

namespace colmap_lidar {
namespace testing {

struct CameraLidarScene {
  std::vector<std::unique_ptr<StationCloud>> clouds;
  std::vector<CameraDepthPoints> points;

  std::vector<const StationCloud*> Clouds() const {
    std::vector<const StationCloud*> pointers;
    for (const auto& cloud : clouds) pointers.push_back(cloud.get());
    return pointers;
  }
};

}  // namespace testing
}  // namespace colmap_lidar
