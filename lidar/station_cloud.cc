#include "lidar/station_cloud.h"

#include "lidar/registration_quality.h"
#include "lidar/util/check_option.h"

#include <stdexcept>

namespace colmap_lidar {

bool StationCloudOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(voxel_size, 0);
  LIDAR_CHECK_OPTION_GT(feature_voxel_size, 0);
  return normals.Check() && keypoints.Check() && bsc.Check();
}

std::unique_ptr<StationCloud> PrepareStationCloud(const PointCloud& raw,
                                                  const StationCloudOptions& options) {
  ThrowUnlessValid(options, "StationCloudOptions");
  if (raw.Empty()) throw std::invalid_argument("PrepareStationCloud: empty cloud");
  auto station = std::make_unique<StationCloud>();
  station->cloud = VoxelDownsample(raw, options.voxel_size);
  station->cloud.normals.clear();
  station->tree = std::make_unique<KdTree3>(station->cloud.points);
  EstimateNormals(*station->tree, options.normals, &station->cloud, &station->curvature);
  station->plane_noise_rms = PlaneNoiseRms(station->cloud, *station->tree);

  if (!options.compute_features) return station;

  // Features on a coarser copy: keypoint PCA and descriptors need metres of support, not millimetres.
  const PointCloud coarse = VoxelDownsample(raw, options.feature_voxel_size);
  const KdTree3 coarse_tree(coarse.points);
  const std::vector<size_t> keypoints = DetectKeypoints(coarse, coarse_tree, options.keypoints);
  station->features =
      ComputeBscFeatures(coarse, coarse_tree, keypoints, options.normals.viewpoint, options.bsc);
  return station;
}

}  // namespace colmap_lidar
