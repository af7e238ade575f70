#include "bridge/initialization/travel_structure_extrinsic.h"

#include "bridge/initialization/image_pair_poses.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/rigid3_isometry.h"
#include "lidar/cloud_io.h"

#include "colmap/geometry/triangulation.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

namespace colmap_lidar {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// One verified image pair with a LiDAR motion: unit travel directions in both frames (signed so
// that all pairs point along the drive) and the metric baseline.
struct DirectionPair {
  colmap::image_t image_id1 = 0, image_id2 = 0;
  Eigen::Vector3d in_cam, in_lidar;
  double baseline_m = 0;
};

using PairKey = std::pair<colmap::image_t, colmap::image_t>;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kDegToRad;
}

// lidar2_from_lidar1 of two images' stations, if both have a LiDAR pose.
std::optional<colmap::Rigid3d> LidarMotion(
    colmap::image_t image_id1,
    colmap::image_t image_id2,
    const std::map<colmap::image_t, std::string>& station_of_image,
    const std::map<std::string, colmap::Rigid3d>& world_from_lidar) {
  const auto station1 = station_of_image.find(image_id1);
  const auto station2 = station_of_image.find(image_id2);
  if (station1 == station_of_image.end() || station2 == station_of_image.end()) return {};
  const auto pose1 = world_from_lidar.find(station1->second);
  const auto pose2 = world_from_lidar.find(station2->second);
  if (pose1 == world_from_lidar.end() || pose2 == world_from_lidar.end()) return {};
  return colmap::Inverse(pose2->second) * pose1->second;
}

std::vector<DirectionPair> CollectDirectionPairs(
    const colmap::Database& database,
    const std::map<colmap::image_t, std::string>& station_of_image,
    const std::map<std::string, colmap::Rigid3d>& world_from_lidar,
    const TravelStructureOptions& options) {
  // The LiDAR motion of each pair that translates and hardly turns: only their poses are estimated.
  std::map<PairKey, colmap::Rigid3d> lidar_motions;
  const auto wanted = [&](colmap::image_t image_id1, colmap::image_t image_id2) {
    const std::optional<colmap::Rigid3d> lidar =
        LidarMotion(image_id1, image_id2, station_of_image, world_from_lidar);
    if (!lidar || lidar->translation.norm() < options.min_translation_m ||
        Eigen::AngleAxisd(lidar->rotation).angle() > options.max_rotation_deg * kDegToRad) {
      return false;
    }
    lidar_motions[{image_id1, image_id2}] = *lidar;
    return true;
  };
  std::vector<DirectionPair> pairs;
  const auto visit = [&](const TwoViewPose& view) {
    const Eigen::Vector3d& b = lidar_motions.at({view.image_id1, view.image_id2}).translation;
    pairs.push_back({view.image_id1,
                     view.image_id2,
                     view.geometry.cam2_from_cam1.translation,
                     b.normalized(),
                     b.norm()});
  };
  ForEachTwoViewPose(database, options.min_inliers, visit, wanted);
  if (pairs.empty()) return pairs;
  // One sign along the drive: that of the longest LiDAR motion.
  const Eigen::Vector3d reference =
      std::max_element(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
        return a.baseline_m < b.baseline_m;
      })->in_lidar;
  for (DirectionPair& pair : pairs) {
    if (pair.in_lidar.dot(reference) >= 0) continue;
    pair.in_cam = -pair.in_cam;
    pair.in_lidar = -pair.in_lidar;
  }
  return pairs;
}

// The pairs within `max_deg` of `cam` and `lidar` in both frames.
std::vector<DirectionPair> Agreeing(const std::vector<DirectionPair>& pairs,
                                    const Eigen::Vector3d& cam,
                                    const Eigen::Vector3d& lidar,
                                    double max_deg) {
  std::vector<DirectionPair> agreeing;
  for (const DirectionPair& pair : pairs) {
    if (AngleDeg(pair.in_cam, cam) <= max_deg && AngleDeg(pair.in_lidar, lidar) <= max_deg) {
      agreeing.push_back(pair);
    }
  }
  return agreeing;
}

// The travel directions: seeded by the pair that most others agree with (at most 500 pairs tried),
// then the mean of the agreeing pairs, repeated until the set is stable.
std::vector<DirectionPair> TravelPairs(const std::vector<DirectionPair>& pairs,
                                       double max_deg,
                                       Eigen::Vector3d* in_cam,
                                       Eigen::Vector3d* in_lidar) {
  const size_t stride = std::max<size_t>(1, pairs.size() / 500);
  size_t best_count = 0;
  for (size_t k = 0; k < pairs.size(); k += stride) {
    const size_t count = Agreeing(pairs, pairs[k].in_cam, pairs[k].in_lidar, max_deg).size();
    if (count <= best_count) continue;
    best_count = count;
    *in_cam = pairs[k].in_cam;
    *in_lidar = pairs[k].in_lidar;
  }
  std::vector<DirectionPair> agreeing;
  for (int iteration = 0; iteration < 10 && best_count > 0; ++iteration) {
    std::vector<DirectionPair> next = Agreeing(pairs, *in_cam, *in_lidar, max_deg);
    if (next.empty()) break;
    Eigen::Vector3d cam_sum = Eigen::Vector3d::Zero(), lidar_sum = Eigen::Vector3d::Zero();
    for (const DirectionPair& pair : next) {
      cam_sum += pair.in_cam;
      lidar_sum += pair.in_lidar;
    }
    *in_cam = cam_sum.normalized();
    *in_lidar = lidar_sum.normalized();
    const bool stable = next.size() == agreeing.size();
    agreeing = std::move(next);
    if (stable) break;
  }
  return agreeing;
}

// The inlier matches of `view`, triangulated in camera 1's frame with the baseline scaled to
// `baseline_m`, with each depth's sigma along its ray (sigma_theta * range * sqrt(2) / sin(angle)).
void Triangulate(const TwoViewPose& view,
                 double baseline_m,
                 const TravelStructureOptions& options,
                 CameraDepthPoints* points) {
  colmap::Rigid3d cam2_from_cam1 = view.geometry.cam2_from_cam1;
  cam2_from_cam1.translation *= baseline_m;
  const Eigen::Matrix3x4d cam1_from_world = colmap::Rigid3d().ToMatrix();
  const Eigen::Matrix3x4d cam2_from_world = cam2_from_cam1.ToMatrix();
  const Eigen::Vector3d center2 = colmap::Inverse(cam2_from_cam1).translation;
  const double sigma_theta = options.sigma_keypoint_px / view.camera1.MeanFocalLength();
  for (const colmap::FeatureMatch& match : view.geometry.inlier_matches) {
    const Eigen::Vector2d x1 = view.camera1.CamFromImg(view.keypoints1[match.point2D_idx1]);
    const Eigen::Vector2d x2 = view.camera2.CamFromImg(view.keypoints2[match.point2D_idx2]);
    const Eigen::Vector3d point =
        colmap::TriangulatePoint(cam1_from_world, cam2_from_world, x1, x2);
    const double angle =
        colmap::CalculateTriangulationAngle(Eigen::Vector3d::Zero(), center2, point);
    if (!(point.z() > 0) || !((cam2_from_cam1 * point).z() > 0) ||
        angle < options.min_triangulation_angle_deg * kDegToRad ||
        point.norm() > options.max_depth_m) {
      continue;
    }
    points->point_in_cam.push_back(point);
    points->sigma_along_ray_m.push_back(sigma_theta * point.norm() * std::sqrt(2.0) /
                                        std::sin(angle));
  }
}

// Camera points of each station (by image id) from the travel pairs.
std::map<colmap::image_t, CameraDepthPoints> TriangulateTravelPairs(
    const colmap::Database& database,
    const std::vector<DirectionPair>& travel_pairs,
    const TravelStructureOptions& options) {
  std::map<PairKey, double> baselines;
  for (const DirectionPair& pair : travel_pairs) {
    baselines[{pair.image_id1, pair.image_id2}] = pair.baseline_m;
  }
  std::map<colmap::image_t, CameraDepthPoints> points;
  ForEachTwoViewPose(
      database,
      options.min_inliers,
      [&](const TwoViewPose& view) {
        Triangulate(
            view, baselines.at({view.image_id1, view.image_id2}), options, &points[view.image_id1]);
      },
      [&](colmap::image_t image_id1, colmap::image_t image_id2) {
        return baselines.count({image_id1, image_id2}) > 0;
      });
  return points;
}

std::string Describe(const TravelStructureExtrinsic& estimate) {
  std::ostringstream text;
  text.precision(3);
  text << "travel direction from " << estimate.num_direction_pairs << " image pairs (rms "
       << estimate.direction_rms_deg << " deg); roll about it " << estimate.roll.best_roll_deg
       << " deg from the structure (rms " << estimate.roll.best_rms_m << " m; next best "
       << estimate.roll.runner_up_roll_deg << " deg, rms " << estimate.roll.runner_up_rms_m
       << " m); aligned with " << estimate.alignment.num_associations << " triangulated points of "
       << estimate.num_stations << " stations, RMS " << 1000 * estimate.alignment.rms_m << " mm";
  return text.str();
}

}  // namespace

bool TravelStructureOptions::Check() const {
  CHECK_OPTION_GE(min_inliers, 5);
  CHECK_OPTION_GT(min_translation_m, 0);
  CHECK_OPTION_GT(max_rotation_deg, 0);
  CHECK_OPTION_GT(max_direction_deviation_deg, 0);
  CHECK_OPTION_GE(min_direction_pairs, 1);
  CHECK_OPTION_GT(min_triangulation_angle_deg, 0);
  CHECK_OPTION_GT(sigma_keypoint_px, 0);
  CHECK_OPTION_GT(max_depth_m, 0);
  CHECK_OPTION_GT(voxel_size_m, 0);
  CHECK_OPTION_GE(min_associations, 6);
  return roll_search.Check() && alignment.Check();
}

namespace {

// Steps 1 and 2 of the header: false (with the message) when too few pairs agree on a direction.
bool EstimateTravel(const std::vector<DirectionPair>& pairs,
                    const TravelStructureOptions& options,
                    std::vector<DirectionPair>* travel_pairs,
                    TravelStructureExtrinsic* estimate) {
  *travel_pairs = TravelPairs(pairs,
                              options.max_direction_deviation_deg,
                              &estimate->travel_in_cam,
                              &estimate->travel_in_lidar);
  estimate->num_direction_pairs = static_cast<int>(travel_pairs->size());
  double squared = 0;
  for (const DirectionPair& pair : *travel_pairs) {
    squared += std::pow(AngleDeg(pair.in_cam, estimate->travel_in_cam), 2);
  }
  estimate->direction_rms_deg =
      travel_pairs->empty() ? 0.0 : std::sqrt(squared / travel_pairs->size());
  if (estimate->num_direction_pairs >= options.min_direction_pairs) return true;
  estimate->message = "only " + std::to_string(estimate->num_direction_pairs) + " of " +
                      std::to_string(pairs.size()) +
                      " image pairs with a LiDAR motion agree on a direction of travel";
  return false;
}

// Roll search and alignment over the stations with triangulated points.
void AlignWithStructure(const std::map<colmap::image_t, CameraDepthPoints>& points_of_image,
                        const std::map<colmap::image_t, std::string>& cloud_of_image,
                        const TravelStructureOptions& options,
                        TravelStructureExtrinsic* estimate) {
  std::vector<CameraDepthPoints> points;
  std::vector<std::unique_ptr<StationCloud>> clouds;
  StationCloudOptions cloud_options;
  cloud_options.voxel_size = options.voxel_size_m;
  cloud_options.compute_features = false;
  for (const auto& [image_id, station_points] : points_of_image) {
    if (station_points.point_in_cam.empty()) continue;
    points.push_back(station_points);
    clouds.push_back(
        PrepareStationCloud(ReadStationCloud(cloud_of_image.at(image_id)), cloud_options));
  }
  estimate->num_stations = static_cast<int>(points.size());
  if (points.empty()) {
    estimate->message = "no image pair along the drive gave triangulated points";
    return;
  }
  std::vector<const StationCloud*> cloud_pointers;
  for (const auto& cloud : clouds) cloud_pointers.push_back(cloud.get());
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.linear() =
      Eigen::Quaterniond::FromTwoVectors(estimate->travel_in_lidar, estimate->travel_in_cam)
          .toRotationMatrix();
  estimate->roll = SearchRollAboutAxis(
      points, cloud_pointers, start, estimate->travel_in_cam, options.roll_search);
  estimate->alignment = AlignCameraPointsWithLidar(
      points, cloud_pointers, estimate->roll.cam_from_lidar, options.alignment);
  estimate->cam_from_lidar = ToRigid3d(estimate->alignment.cam_from_lidar);
  estimate->message = Describe(*estimate);
  if (estimate->alignment.num_associations < static_cast<size_t>(options.min_associations)) {
    estimate->message = "only " + std::to_string(estimate->alignment.num_associations) +
                        " triangulated points on LiDAR planes (at least " +
                        std::to_string(options.min_associations) + " needed): " + estimate->message;
    return;
  }
  estimate->valid = true;
}

}  // namespace

TravelStructureExtrinsic EstimateExtrinsicFromTravelAndStructure(
    const colmap::Database& database,
    const StationDataset& dataset,
    const std::map<std::string, colmap::Rigid3d>& world_from_lidar,
    const std::map<std::string, colmap::image_t>& image_of_station,
    const TravelStructureOptions& options) {
  THROW_CHECK(options.Check());
  std::map<colmap::image_t, std::string> station_of_image, cloud_of_image;
  for (size_t k = 0; k < dataset.stations.size(); ++k) {
    const auto image = image_of_station.find(dataset.stations[k]);
    if (image == image_of_station.end()) continue;
    station_of_image[image->second] = dataset.stations[k];
    cloud_of_image[image->second] = dataset.cloud_paths[k];
  }
  TravelStructureExtrinsic estimate;
  std::vector<DirectionPair> travel_pairs;
  if (!EstimateTravel(CollectDirectionPairs(database, station_of_image, world_from_lidar, options),
                      options,
                      &travel_pairs,
                      &estimate)) {
    return estimate;
  }
  std::cout << "  travel direction from " << travel_pairs.size()
            << " image pairs; triangulating their matches" << std::endl;
  AlignWithStructure(
      TriangulateTravelPairs(database, travel_pairs, options), cloud_of_image, options, &estimate);
  return estimate;
}

}  // namespace colmap_lidar
