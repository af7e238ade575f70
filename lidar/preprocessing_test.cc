#include "lidar/preprocessing.h"

#include "tests/testing/synthetic_clouds.h"

#include <gtest/gtest.h>
#include <pcl/features/normal_3d.h>
#include <pcl/point_types.h>

namespace colmap_lidar {
namespace {

TEST(PreprocessingTest, VoxelDownsampleAveragesEachVoxel) {
  PointCloud cloud;
  // Two voxels of 0.5 m: two points in the first, three in the second.
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.1, 0.1, 0.1),
                                   Eigen::Vector3d(0.3, 0.1, 0.1),
                                   Eigen::Vector3d(1.1, 0.2, 0.1),
                                   Eigen::Vector3d(1.2, 0.3, 0.1),
                                   Eigen::Vector3d(1.3, 0.4, 0.1)}) {
    cloud.points.push_back(p);
    cloud.intensities.push_back(static_cast<float>(p.x() * 10));
  }
  const PointCloud down = VoxelDownsample(cloud, 0.5);
  ASSERT_EQ(down.Size(), 2u);
  EXPECT_TRUE(down.points[0].isApprox(Eigen::Vector3d(0.2, 0.1, 0.1)));
  EXPECT_TRUE(down.points[1].isApprox(Eigen::Vector3d(1.2, 0.3, 0.1)));
  EXPECT_FLOAT_EQ(down.intensities[1], 12.f);
  EXPECT_THROW(VoxelDownsample(cloud, 0), std::invalid_argument);
}

TEST(PreprocessingTest, NormalsOnATiltedNoisyPlaneFaceTheSensor) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::normal_distribution<double> noise(0, 0.002);
  const Eigen::Vector3d normal = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  PointCloud cloud;
  for (int i = 0; i < 20000; ++i) {
    cloud.points.push_back(Eigen::Vector3d(1, 2, 3) + unit(rng) * u + unit(rng) * v +
                           noise(rng) * normal);
  }
  const KdTree3 tree(cloud.points);
  NormalEstimationOptions options;
  options.viewpoint = Eigen::Vector3d(1, 2, 3) - 5 * normal;  // the sensor is on the -normal side
  std::vector<double> curvature;
  EstimateNormals(tree, options, &cloud, &curvature);
  double worst_deg = 0;
  for (size_t i = 0; i < cloud.Size(); ++i) {
    EXPECT_LT(cloud.normals[i].dot(normal), 0) << "normal not oriented towards the sensor";
    worst_deg =
        std::max(worst_deg, std::acos(std::min(1.0, -cloud.normals[i].dot(normal))) * 180 / M_PI);
  }
  // 2 mm noise over kNN patches of ~2 cm: a few degrees at worst.
  EXPECT_LT(worst_deg, 12.0);
  EXPECT_LT(*std::max_element(curvature.begin(), curvature.end()), 0.05);
}

TEST(PreprocessingTest, NormalsAgreeWithPcl) {
  PointCloud cloud = testing::SyntheticRoom(400, 2, 0.001);
  cloud.normals.clear();
  const KdTree3 tree(cloud.points);
  NormalEstimationOptions options;
  options.radius = 0.1;
  EstimateNormals(tree, options, &cloud);

  pcl::PointCloud<pcl::PointXYZ>::Ptr pcl_cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (const Eigen::Vector3d& p : cloud.points)
    pcl_cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimator;
  estimator.setInputCloud(pcl_cloud);
  estimator.setRadiusSearch(0.1);
  estimator.setViewPoint(0, 0, 0);
  pcl::PointCloud<pcl::Normal> pcl_normals;
  estimator.compute(pcl_normals);

  size_t compared = 0, agree = 0, same_orientation = 0;
  for (size_t i = 0; i < cloud.Size(); ++i) {
    const auto& n = pcl_normals[i];
    if (!std::isfinite(n.normal_x) || cloud.normals[i].squaredNorm() < 0.5) continue;
    const Eigen::Vector3d pcl_normal(n.normal_x, n.normal_y, n.normal_z);
    const double dot = cloud.normals[i].dot(pcl_normal);
    ++compared;
    agree += std::abs(dot) > std::cos(0.5 * M_PI / 180);
    same_orientation += dot > 0;
  }
  ASSERT_GT(compared, cloud.Size() * 9 / 10);
  EXPECT_GT(agree, compared * 99 / 100);
  EXPECT_GT(same_orientation, compared * 99 / 100);
}

TEST(PreprocessingTest, StatisticalOutlierRemovalDropsIsolatedPoints) {
  PointCloud cloud = testing::SyntheticRoom(200, 3);
  const size_t num_surface = cloud.Size();
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int i = 0; i < 50; ++i) {
    // Floating in free space, at least 0.5 m from every surface of the room.
    cloud.points.emplace_back(3 * unit(rng), 0.8 * unit(rng), 3 + 0.5 * unit(rng));
    cloud.normals.emplace_back(0, 0, 1);
  }
  const KdTree3 tree(cloud.points);
  const std::vector<size_t> inliers = StatisticalInliers(cloud, tree, OutlierRemovalOptions());
  size_t kept_outliers = 0;
  for (size_t i : inliers) kept_outliers += i >= num_surface;
  EXPECT_EQ(kept_outliers, 0u);
  EXPECT_GT(inliers.size(), num_surface * 97 / 100);
  EXPECT_EQ(SelectPoints(cloud, inliers).Size(), inliers.size());
}

}  // namespace
}  // namespace colmap_lidar
