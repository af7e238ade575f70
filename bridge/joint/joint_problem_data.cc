#include "bridge/joint/joint_problem_data.h"

#include "colmap_ext/colmap_tables.h"
#include "colmap_ext/extension_database.h"
#include "colmap_ext/logging.h"
#include "lidar/cloud_io.h"
#include "lidar/kd_tree.h"

#include <filesystem>
#include <iostream>
#include <set>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// Fraction of up to 500 source points with a target point within `distance` under target_from_source.
double Overlap(const StationCloud& target,
               const StationCloud& source,
               const colmap::Rigid3d& target_from_source,
               double distance) {
  const size_t n = source.cloud.Size();
  if (n == 0) return 0;
  const size_t num_samples = std::min<size_t>(500, n);
  size_t num_close = 0;
  for (size_t k = 0; k < num_samples; ++k) {
    const Eigen::Vector3d point = target_from_source * source.cloud.points[k * n / num_samples];
    size_t index = 0;
    double squared_distance = 0;
    if (target.tree->Nearest(point, &index, &squared_distance) &&
        squared_distance <= distance * distance) {
      ++num_close;
    }
  }
  return static_cast<double>(num_close) / num_samples;
}

using ImagePairSet = std::set<std::pair<colmap::image_t, colmap::image_t>>;

// The station index of each registered image, by the image name's stem.
std::map<colmap::image_t, size_t> StationOfImage(const StationDataset& dataset,
                                                 const colmap::Reconstruction& reconstruction,
                                                 const std::vector<colmap::image_t>& image_ids) {
  std::map<std::string, size_t> station_index;
  for (size_t i = 0; i < dataset.stations.size(); ++i) station_index[dataset.stations[i]] = i;
  std::map<colmap::image_t, size_t> station_of_image;
  for (const colmap::image_t image_id : image_ids) {
    const std::string& name = reconstruction.Image(image_id).Name();
    const auto it = station_index.find(fs::path(name).stem().string());
    if (it == station_index.end()) {
      throw std::runtime_error("registered image '" + name + "' is not a station of " +
                               dataset.root);
    }
    station_of_image[image_id] = it->second;
  }
  return station_of_image;
}

// The model's image ids must be the database's (depth priors and matches are keyed by them).
void CheckModelIsFromDatabase(const std::string& database_path,
                              const colmap::Reconstruction& reconstruction,
                              const std::vector<colmap::image_t>& image_ids) {
  const std::map<colmap::image_t, std::string> names = ReadImageNames(database_path);
  for (const colmap::image_t image_id : image_ids) {
    const std::string& name = reconstruction.Image(image_id).Name();
    const auto it = names.find(image_id);
    if (it == names.end() || it->second != name) {
      throw std::runtime_error("image " + std::to_string(image_id) + " ('" + name +
                               "') of the model is not the same image in " + database_path +
                               ": the model was not made from this database");
    }
  }
}

void ReadDepthPriors(const std::string& database_path,
                     const std::vector<colmap::image_t>& image_ids,
                     JointProblemData* data) {
  const ExtensionDatabase extension(database_path, ExtensionDatabase::Mode::kReadOnly);
  size_t num_priors = 0;
  for (const colmap::image_t image_id : image_ids) {
    auto& priors = data->depth_priors[image_id];
    for (const DepthPrior& prior : extension.ReadDepthPriors(image_id)) {
      priors[prior.point2D_idx] = prior;
    }
    num_priors += priors.size();
  }
  std::cout << "Depth priors: " << num_priors << " for " << image_ids.size() << " registered images"
            << std::endl;
}

// A_c: COLMAP's verified pairs between registered images with enough inliers.
ImagePairSet VerifiedImagePairs(const std::string& database_path,
                                const std::map<colmap::image_t, size_t>& station_of_image,
                                int min_inliers) {
  ImagePairSet pairs;
  for (const VerifiedPairInliers& pair : ReadVerifiedPairInliers(database_path)) {
    if (!station_of_image.count(pair.image_id1) || !station_of_image.count(pair.image_id2))
      continue;
    if (pair.num_inliers < min_inliers) continue;
    pairs.insert({pair.image_id1, pair.image_id2});
  }
  return pairs;
}

// Clouds, one station at a time (the raw cloud is dropped after downsampling).
void LoadClouds(const StationDataset& dataset,
                const std::vector<colmap::image_t>& image_ids,
                const std::map<colmap::image_t, size_t>& station_of_image,
                double voxel_size_m,
                LoadedJointData* loaded) {
  StationCloudOptions cloud_options;
  cloud_options.voxel_size = voxel_size_m;
  cloud_options.compute_features = false;
  for (const colmap::image_t image_id : image_ids) {
    const size_t station = station_of_image.at(image_id);
    const PointCloud raw = ReadStationCloud(dataset.cloud_paths[station]);
    loaded->clouds.push_back(PrepareStationCloud(raw, cloud_options));
    loaded->data.clouds[image_id] = loaded->clouds.back().get();
    std::cout << "  cloud " << dataset.stations[station] << ": " << raw.Size() << " points -> "
              << loaded->clouds.back()->cloud.Size() << " after " << voxel_size_m << " m voxels"
              << std::endl;
  }
}

// A_l: overlapping clouds under the initial estimate; each station keeps its `max_lidar_neighbors`
// most overlapping partners (all stations of a courtyard overlap; the term needs a connected graph,
// not every pair).
ImagePairSet OverlappingLidarPairs(const colmap::Reconstruction& reconstruction,
                                   const std::vector<colmap::image_t>& image_ids,
                                   const colmap::Rigid3d& cam_from_lidar,
                                   const std::map<colmap::image_t, const StationCloud*>& clouds,
                                   const JointDataOptions& options) {
  // Candidates: each station's nearest stations by position (four times the neighbours kept), so
  // that the overlap tests grow as N, not N^2, on large surveys.
  std::vector<colmap::Rigid3d> world_from_lidar;
  std::vector<Eigen::Vector3d> positions;
  for (const colmap::image_t image_id : image_ids) {
    world_from_lidar.push_back(colmap::Inverse(reconstruction.Image(image_id).CamFromWorld()) *
                               cam_from_lidar);
    positions.push_back(world_from_lidar.back().translation);
  }
  const KdTree3 position_tree(positions);
  const size_t num_candidates = 4 * static_cast<size_t>(options.max_lidar_neighbors) + 1;
  std::set<std::pair<size_t, size_t>> candidates;
  for (size_t a = 0; a < image_ids.size(); ++a) {
    std::vector<size_t> nearest;
    std::vector<double> squared;
    position_tree.KNearest(positions[a], num_candidates, &nearest, &squared);
    for (const size_t b : nearest) {
      if (b != a) candidates.insert({std::min(a, b), std::max(a, b)});
    }
  }
  std::vector<std::vector<std::pair<double, size_t>>> partners(image_ids.size());
  for (const auto& [a, b] : candidates) {
    const double overlap = Overlap(*clouds.at(image_ids[a]),
                                   *clouds.at(image_ids[b]),
                                   colmap::Inverse(world_from_lidar[a]) * world_from_lidar[b],
                                   options.lidar_overlap_distance_m);
    if (overlap >= options.min_lidar_overlap) {
      partners[a].emplace_back(overlap, b);
      partners[b].emplace_back(overlap, a);
    }
  }
  ImagePairSet lidar_pairs;
  for (size_t a = 0; a < image_ids.size(); ++a) {
    std::sort(partners[a].rbegin(), partners[a].rend());
    const size_t keep = std::min(partners[a].size(), size_t(options.max_lidar_neighbors));
    for (size_t k = 0; k < keep; ++k) {
      const colmap::image_t other = image_ids[partners[a][k].second];
      lidar_pairs.insert({std::min(image_ids[a], other), std::max(image_ids[a], other)});
    }
  }
  return lidar_pairs;
}

}  // namespace

bool JointDataOptions::Check() const {
  CHECK_OPTION_GE(min_image_pair_inliers, 0);
  CHECK_OPTION_GT(lidar_overlap_distance_m, 0);
  CHECK_OPTION_GE(min_lidar_overlap, 0);
  CHECK_OPTION_GT(voxel_size_m, 0);
  CHECK_OPTION_GT(max_lidar_neighbors, 0);
  return true;
}

std::unique_ptr<LoadedJointData> LoadJointProblemData(const std::string& database_path,
                                                      const StationDataset& dataset,
                                                      const colmap::Reconstruction& reconstruction,
                                                      const colmap::Rigid3d& cam_from_lidar,
                                                      bool load_clouds,
                                                      const JointDataOptions& options) {
  THROW_CHECK(options.Check());
  THROW_CHECK(fs::is_regular_file(database_path))
      << "Database file does not exist: " << database_path;
  auto loaded = std::make_unique<LoadedJointData>();
  std::vector<colmap::image_t> image_ids = reconstruction.RegImageIds();
  std::sort(image_ids.begin(), image_ids.end());
  loaded->station_of_image = StationOfImage(dataset, reconstruction, image_ids);
  const std::map<colmap::image_t, size_t>& station_of_image = loaded->station_of_image;
  CheckModelIsFromDatabase(database_path, reconstruction, image_ids);
  ImagePairSet pairs =
      VerifiedImagePairs(database_path, station_of_image, options.min_image_pair_inliers);
  ReadDepthPriors(database_path, image_ids, &loaded->data);
  loaded->data.stereo_baseline_focal = dataset.rig.BaselineFocal();
  loaded->num_image_pairs = pairs.size();
  if (load_clouds) {
    LoadClouds(dataset, image_ids, station_of_image, options.voxel_size_m, loaded.get());
    const ImagePairSet lidar_pairs = OverlappingLidarPairs(
        reconstruction, image_ids, cam_from_lidar, loaded->data.clouds, options);
    loaded->num_lidar_pairs = lidar_pairs.size();
    pairs.insert(lidar_pairs.begin(), lidar_pairs.end());
  }
  loaded->data.pairs.assign(pairs.begin(), pairs.end());
  if (load_clouds) {
    std::cout << "Pose graph: " << loaded->num_image_pairs << " image pairs (A_c), "
              << loaded->num_lidar_pairs << " overlapping LiDAR pairs (A_l), "
              << loaded->data.pairs.size() << " pairs in A_c v A_l" << std::endl;
  }
  return loaded;
}

}  // namespace colmap_lidar
