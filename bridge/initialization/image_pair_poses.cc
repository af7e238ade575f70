#include "bridge/initialization/image_pair_poses.h"

#include "colmap_ext/logging.h"

#include "colmap/estimators/two_view_geometry.h"

#include <Eigen/Geometry>

#include <random>

namespace colmap_lidar {

namespace {

colmap::Rigid3d Umeyama(const Eigen::Matrix3Xd& target, const Eigen::Matrix3Xd& source) {
  const Eigen::Matrix4d t = Eigen::umeyama(source, target, /*with_scaling=*/false);
  return colmap::Rigid3d(Eigen::Quaterniond(t.topLeftCorner<3, 3>()), t.topRightCorner<3, 1>());
}

// The 3D points of the pair's inlier matches with a depth prior in both images, in each camera.
struct MatchedPoints {
  std::vector<Eigen::Vector3d> in_i, in_j;
};

// One image's keypoints, depth priors and camera.
struct ImageWithDepth {
  const colmap::FeatureKeypoints& keypoints;
  const std::unordered_map<colmap::point2D_t, DepthPrior>& priors;
  const colmap::Camera& camera;
};

// The inlier matches of the pair with a depth prior in both images, as 3D points in each camera.
MatchedPoints PointsWithDepth(const colmap::TwoViewGeometry& geometry,
                              const ImageWithDepth& image_i,
                              const ImageWithDepth& image_j) {
  MatchedPoints points;
  for (const colmap::FeatureMatch& match : geometry.inlier_matches) {
    const auto prior_i = image_i.priors.find(match.point2D_idx1);
    const auto prior_j = image_j.priors.find(match.point2D_idx2);
    if (prior_i == image_i.priors.end() || prior_j == image_j.priors.end()) continue;
    const colmap::FeatureKeypoint& ki = image_i.keypoints.at(match.point2D_idx1);
    const colmap::FeatureKeypoint& kj = image_j.keypoints.at(match.point2D_idx2);
    points.in_i.push_back(prior_i->second.depth *
                          image_i.camera.CamFromImg(Eigen::Vector2d(ki.x, ki.y)).homogeneous());
    points.in_j.push_back(prior_j->second.depth *
                          image_j.camera.CamFromImg(Eigen::Vector2d(kj.x, kj.y)).homogeneous());
  }
  return points;
}

// RANSAC over minimal 3-point Umeyama fits, then 3 refits on the inliers; false below min_inliers.
// An inlier lies within max_relative_error of its depth.
bool FitRelativePose(const MatchedPoints& points,
                     const ImagePairPoseOptions& options,
                     std::mt19937_64* rng,
                     ImagePairPose* pose) {
  const int n = static_cast<int>(points.in_i.size());
  if (n < options.min_inliers) return false;
  const auto inliers_of = [&](const colmap::Rigid3d& i_from_j) {
    std::vector<int> inliers;
    for (int k = 0; k < n; ++k) {
      if ((points.in_i[k] - i_from_j * points.in_j[k]).norm() <=
          options.max_relative_error * points.in_i[k].z()) {
        inliers.push_back(k);
      }
    }
    return inliers;
  };
  const auto fit = [&](const std::vector<int>& indices) {
    Eigen::Matrix3Xd target(3, indices.size()), source(3, indices.size());
    for (size_t k = 0; k < indices.size(); ++k) {
      target.col(k) = points.in_i[indices[k]];
      source.col(k) = points.in_j[indices[k]];
    }
    return Umeyama(target, source);
  };
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::vector<int> best;
  for (int iteration = 0; iteration < options.num_ransac_iterations; ++iteration) {
    const int a = pick(*rng), b = pick(*rng), c = pick(*rng);
    if (a == b || b == c || a == c) continue;
    std::vector<int> inliers = inliers_of(fit({a, b, c}));
    if (inliers.size() > best.size()) best = std::move(inliers);
  }
  for (int refinement = 0; refinement < 3; ++refinement) {
    if (static_cast<int>(best.size()) < options.min_inliers) return false;
    pose->cam_i_from_cam_j = fit(best);
    best = inliers_of(pose->cam_i_from_cam_j);
  }
  if (static_cast<int>(best.size()) < options.min_inliers) return false;
  pose->num_correspondences = n;
  pose->num_inliers = static_cast<int>(best.size());
  double squared = 0;
  for (const int k : best) {
    squared += (points.in_i[k] - pose->cam_i_from_cam_j * points.in_j[k]).squaredNorm();
  }
  pose->rms_m = std::sqrt(squared / best.size());
  return true;
}

}  // namespace

bool ImagePairPoseOptions::Check() const {
  CHECK_OPTION_GE(min_inliers, 3);
  CHECK_OPTION_GT(max_relative_error, 0);
  CHECK_OPTION_GT(num_ransac_iterations, 0);
  return true;
}

std::vector<ImagePairPose> EstimateImagePairPoses(const colmap::Database& database,
                                                  const DepthPriorsByImage& depth_priors,
                                                  const ImagePairPoseOptions& options) {
  THROW_CHECK(options.Check());
  std::unordered_map<colmap::image_t, colmap::Image> images;
  std::unordered_map<colmap::camera_t, colmap::Camera> cameras;
  for (const colmap::Image& image : database.ReadAllImages()) images[image.ImageId()] = image;
  for (const colmap::Camera& camera : database.ReadAllCameras()) {
    cameras[camera.camera_id] = camera;
  }
  std::vector<colmap::image_pair_t> pair_ids;
  std::vector<colmap::TwoViewGeometry> geometries;
  database.ReadTwoViewGeometries(&pair_ids, &geometries);
  // Each image's keypoints are read once, not once per pair.
  std::unordered_map<colmap::image_t, colmap::FeatureKeypoints> keypoints;
  const auto keypoints_of = [&](colmap::image_t image_id) -> const colmap::FeatureKeypoints& {
    auto it = keypoints.find(image_id);
    if (it == keypoints.end()) {
      it = keypoints.emplace(image_id, database.ReadKeypoints(image_id)).first;
    }
    return it->second;
  };
  std::mt19937_64 rng(options.seed);
  std::vector<ImagePairPose> poses;
  for (size_t p = 0; p < pair_ids.size(); ++p) {
    const auto [image_i, image_j] = colmap::Database::PairIdToImagePair(pair_ids[p]);
    const auto priors_i = depth_priors.find(image_i);
    const auto priors_j = depth_priors.find(image_j);
    if (priors_i == depth_priors.end() || priors_j == depth_priors.end()) continue;
    const MatchedPoints points = PointsWithDepth(
        geometries[p],
        {keypoints_of(image_i), priors_i->second, cameras.at(images.at(image_i).CameraId())},
        {keypoints_of(image_j), priors_j->second, cameras.at(images.at(image_j).CameraId())});
    ImagePairPose pose;
    pose.image_i = image_i;
    pose.image_j = image_j;
    if (FitRelativePose(points, options, &rng, &pose)) poses.push_back(pose);
  }
  return poses;
}

void ForEachTwoViewPose(const colmap::Database& database,
                        int min_inliers,
                        const std::function<void(const TwoViewPose&)>& visit,
                        const std::function<bool(colmap::image_t, colmap::image_t)>& wanted) {
  std::vector<colmap::image_pair_t> pair_ids;
  std::vector<colmap::TwoViewGeometry> geometries;
  database.ReadTwoViewGeometries(&pair_ids, &geometries);
  // Each image's keypoints read once, however many pairs it is in.
  std::unordered_map<colmap::image_t, std::vector<Eigen::Vector2d>> keypoints;
  const auto keypoints_of = [&](colmap::image_t image_id) -> const std::vector<Eigen::Vector2d>& {
    auto [it, inserted] = keypoints.try_emplace(image_id);
    if (inserted) {
      for (const colmap::FeatureKeypoint& keypoint : database.ReadKeypoints(image_id)) {
        it->second.emplace_back(keypoint.x, keypoint.y);
      }
    }
    return it->second;
  };
  for (size_t k = 0; k < pair_ids.size(); ++k) {
    colmap::TwoViewGeometry& geometry = geometries[k];
    if (static_cast<int>(geometry.inlier_matches.size()) < min_inliers) continue;
    const auto [image_id1, image_id2] = colmap::Database::PairIdToImagePair(pair_ids[k]);
    if (wanted && !wanted(image_id1, image_id2)) continue;
    const colmap::Camera camera1 = database.ReadCamera(database.ReadImage(image_id1).CameraId());
    const colmap::Camera camera2 = database.ReadCamera(database.ReadImage(image_id2).CameraId());
    if (!colmap::EstimateTwoViewGeometryPose(
            camera1, keypoints_of(image_id1), camera2, keypoints_of(image_id2), &geometry) ||
        !(geometry.cam2_from_cam1.translation.norm() > 0)) {
      continue;
    }
    geometry.cam2_from_cam1.translation.normalize();
    visit({image_id1,
           image_id2,
           camera1,
           camera2,
           keypoints_of(image_id1),
           keypoints_of(image_id2),
           geometry});
  }
}

std::vector<ImagePairPose> EstimateImagePairDirections(const colmap::Database& database,
                                                       int min_inliers) {
  std::vector<ImagePairPose> poses;
  ForEachTwoViewPose(database, min_inliers, [&](const TwoViewPose& pair) {
    ImagePairPose pose;
    // cam2_from_cam1 = cam_{image 2}_from_cam_{image 1}: image_i = image 2, image_j = image 1.
    pose.image_i = pair.image_id2;
    pose.image_j = pair.image_id1;
    pose.cam_i_from_cam_j = pair.geometry.cam2_from_cam1;
    pose.num_inliers = static_cast<int>(pair.geometry.inlier_matches.size());
    poses.push_back(pose);
  });
  return poses;
}

}  // namespace colmap_lidar
