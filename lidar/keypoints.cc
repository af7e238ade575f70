#include "lidar/keypoints.h"

#include "lidar/util/check_option.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace colmap_lidar {

bool KeypointOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(radius, 0);
  LIDAR_CHECK_OPTION_GE(nms_radius, 0);
  LIDAR_CHECK_OPTION_GE(min_neighbors, 3);
  LIDAR_CHECK_OPTION_GT(max_ratio_21, 0);
  LIDAR_CHECK_OPTION_GT(max_ratio_32, 0);
  LIDAR_CHECK_OPTION_GT(max_keypoints, 0);
  return true;
}

std::vector<size_t> DetectKeypoints(const PointCloud& cloud,
                                    const KdTree3& tree,
                                    const KeypointOptions& options) {
  ThrowUnlessValid(options, "KeypointOptions");
  std::vector<double> curvature(cloud.Size(), -1);  // -1: not a candidate
#pragma omp parallel
  {
    std::vector<size_t> neighbors;
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < cloud.Size(); ++i) {
      tree.RadiusSearch(cloud.points[i], options.radius, &neighbors);
      if (static_cast<int>(neighbors.size()) <= options.min_neighbors) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (size_t j : neighbors) mean += cloud.points[j];
      mean /= neighbors.size();
      Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
      for (size_t j : neighbors) {
        const Eigen::Vector3d d = cloud.points[j] - mean;
        covariance += d * d.transpose();
      }
      const Eigen::Vector3d ascending =
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance, Eigen::EigenvaluesOnly)
              .eigenvalues()
              .cwiseMax(0);
      const double l1 = ascending(2), l2 = ascending(1), l3 = ascending(0);
      if (l1 <= 0 || l2 <= 0) continue;
      if (l2 / l1 < options.max_ratio_21 && l3 / l2 < options.max_ratio_32) {
        curvature[i] = l3 / (l1 + l2 + l3);
      }
    }
  }
  std::vector<size_t> candidates;
  for (size_t i = 0; i < cloud.Size(); ++i) {
    if (curvature[i] >= 0) candidates.push_back(i);
  }
  std::stable_sort(candidates.begin(), candidates.end(), [&](size_t a, size_t b) {
    return curvature[a] > curvature[b];
  });
  // Greedy NMS: take the strongest remaining, suppress its neighbours.
  std::vector<char> suppressed(cloud.Size(), 0);
  std::vector<size_t> keypoints;
  std::vector<size_t> neighbors;
  for (size_t i : candidates) {
    if (suppressed[i]) continue;
    keypoints.push_back(i);
    if (keypoints.size() >= options.max_keypoints) break;
    tree.RadiusSearch(cloud.points[i], options.nms_radius, &neighbors);
    for (size_t j : neighbors) suppressed[j] = 1;
  }
  return keypoints;
}

}  // namespace colmap_lidar
