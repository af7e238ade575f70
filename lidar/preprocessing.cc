#include "lidar/preprocessing.h"

#include "lidar/util/check_option.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace colmap_lidar {
namespace {

struct VoxelKeyHash {
  size_t operator()(const Eigen::Vector3i& key) const {
    return static_cast<size_t>(key.x()) * 73856093u ^ static_cast<size_t>(key.y()) * 19349663u ^
           static_cast<size_t>(key.z()) * 83492791u;
  }
};

struct VoxelSum {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d color = Eigen::Vector3d::Zero();
  double intensity = 0;
  int count = 0;
};

}  // namespace

PointCloud VoxelDownsample(const PointCloud& cloud, double voxel_size) {
  if (!(voxel_size > 0)) throw std::invalid_argument("VoxelDownsample: voxel_size must be > 0");
  cloud.CheckConsistent();
  std::unordered_map<Eigen::Vector3i, VoxelSum, VoxelKeyHash> voxels;
  voxels.reserve(cloud.Size() / 4 + 1);
  std::vector<Eigen::Vector3i> order;  // first-seen order: deterministic output
  for (size_t i = 0; i < cloud.Size(); ++i) {
    const Eigen::Vector3i key = (cloud.points[i] / voxel_size).array().floor().cast<int>();
    auto [it, inserted] = voxels.try_emplace(key);
    if (inserted) order.push_back(key);
    VoxelSum& sum = it->second;
    sum.point += cloud.points[i];
    if (cloud.HasNormals()) sum.normal += cloud.normals[i];
    if (cloud.HasColors()) sum.color += cloud.colors[i].cast<double>();
    if (cloud.HasIntensities()) sum.intensity += cloud.intensities[i];
    ++sum.count;
  }
  PointCloud result;
  result.Reserve(order.size(), cloud.HasNormals(), cloud.HasColors(), cloud.HasIntensities());
  for (const Eigen::Vector3i& key : order) {
    const VoxelSum& sum = voxels.at(key);
    result.points.push_back(sum.point / sum.count);
    if (cloud.HasNormals()) {
      const double norm = sum.normal.norm();
      result.normals.push_back(norm > 0 ? Eigen::Vector3d(sum.normal / norm)
                                        : Eigen::Vector3d::Zero());
    }
    if (cloud.HasColors())
      result.colors.push_back((sum.color / sum.count).array().round().cast<uint8_t>());
    if (cloud.HasIntensities())
      result.intensities.push_back(static_cast<float>(sum.intensity / sum.count));
  }
  return result;
}

bool NormalEstimationOptions::Check() const {
  LIDAR_CHECK_OPTION_GE(num_neighbors, 3);
  LIDAR_CHECK_OPTION_GE(radius, 0);
  LIDAR_CHECK_OPTION_GE(min_neighbors, 3);
  LIDAR_CHECK_OPTION(viewpoint.allFinite());
  return true;
}

void EstimateNormals(const KdTree3& tree,
                     const NormalEstimationOptions& options,
                     PointCloud* cloud,
                     std::vector<double>* curvature) {
  ThrowUnlessValid(options, "NormalEstimationOptions");
  if (tree.Size() != cloud->Size()) {
    throw std::invalid_argument("EstimateNormals: the k-d tree is not built over this cloud");
  }
  const std::vector<Eigen::Vector3d>& points = cloud->points;
  cloud->normals.assign(points.size(), Eigen::Vector3d::Zero());
  if (curvature) curvature->assign(points.size(), 1.0);
#pragma omp parallel
  {
    std::vector<size_t> indices;
    std::vector<double> squared;
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < points.size(); ++i) {
      if (options.radius > 0) {
        tree.RadiusSearch(points[i], options.radius, &indices);
      } else {
        tree.KNearest(points[i], options.num_neighbors, &indices, &squared);
      }
      if (static_cast<int>(indices.size()) < options.min_neighbors) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (size_t j : indices) mean += points[j];
      mean /= indices.size();
      Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
      for (size_t j : indices) {
        const Eigen::Vector3d d = points[j] - mean;
        covariance += d * d.transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
      Eigen::Vector3d normal = solver.eigenvectors().col(0);  // eigenvalues ascending
      if (normal.dot(options.viewpoint - points[i]) < 0) normal = -normal;
      cloud->normals[i] = normal;
      if (curvature) {
        const double sum = solver.eigenvalues().sum();
        (*curvature)[i] = sum > 0 ? std::max(0.0, solver.eigenvalues()(0)) / sum : 0;
      }
    }
  }
}

std::vector<size_t> StatisticalInliers(const PointCloud& cloud,
                                       const KdTree3& tree,
                                       const OutlierRemovalOptions& options) {
  std::vector<double> mean_distance(cloud.Size(), 0);
#pragma omp parallel
  {
    std::vector<size_t> indices;
    std::vector<double> squared;
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < cloud.Size(); ++i) {
      tree.KNearest(cloud.points[i], options.num_neighbors + 1, &indices, &squared);
      double sum = 0;
      for (size_t k = 1; k < squared.size(); ++k) sum += std::sqrt(squared[k]);
      mean_distance[i] = squared.size() > 1 ? sum / (squared.size() - 1) : 0;
    }
  }
  double mean = 0, mean_squared = 0;
  for (double d : mean_distance) {
    mean += d;
    mean_squared += d * d;
  }
  mean /= std::max<size_t>(1, cloud.Size());
  const double std_dev =
      std::sqrt(std::max(0.0, mean_squared / std::max<size_t>(1, cloud.Size()) - mean * mean));
  const double limit = mean + options.std_ratio * std_dev;
  std::vector<size_t> inliers;
  for (size_t i = 0; i < cloud.Size(); ++i) {
    if (mean_distance[i] <= limit) inliers.push_back(i);
  }
  return inliers;
}

PointCloud SelectPoints(const PointCloud& cloud, const std::vector<size_t>& indices) {
  PointCloud result;
  result.Reserve(indices.size(), cloud.HasNormals(), cloud.HasColors(), cloud.HasIntensities());
  for (size_t i : indices) {
    result.points.push_back(cloud.points.at(i));
    if (cloud.HasNormals()) result.normals.push_back(cloud.normals[i]);
    if (cloud.HasColors()) result.colors.push_back(cloud.colors[i]);
    if (cloud.HasIntensities()) result.intensities.push_back(cloud.intensities[i]);
  }
  return result;
}

}  // namespace colmap_lidar
