#include "lidar/bsc_descriptor.h"

#include "lidar/keypoints.h"
#include "lidar/preprocessing.h"
#include "tests/testing/synthetic_clouds.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <iostream>

namespace colmap_lidar {
namespace {

struct Described {
  PointCloud cloud;
  std::vector<BscFeature> features;
};

// Describes `cloud` at the given keypoint indices, as seen from `viewpoint`.
std::vector<BscFeature> Describe(const PointCloud& cloud,
                                 const std::vector<size_t>& keypoints,
                                 const Eigen::Vector3d& viewpoint) {
  const KdTree3 tree(cloud.points);
  return ComputeBscFeatures(cloud, tree, keypoints, viewpoint, BscOptions());
}

double MeanDistance(const std::vector<BscFeature>& a, const std::vector<BscFeature>& b, int shift) {
  double sum = 0;
  for (size_t k = 0; k < a.size(); ++k) sum += BscDistance(a[k], b[(k + shift) % b.size()]);
  return sum / a.size();
}

class BscDescriptorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    cloud_ = VoxelDownsample(testing::SyntheticRoom(600, 21), 0.1);
    const KdTree3 tree(cloud_.points);
    keypoints_ = DetectKeypoints(cloud_, tree, KeypointOptions());
    features_ = Describe(cloud_, keypoints_, viewpoint_);
  }
  PointCloud cloud_;
  std::vector<size_t> keypoints_;
  std::vector<BscFeature> features_;
  const Eigen::Vector3d viewpoint_ = Eigen::Vector3d(0.3, -0.2, 1.5);
};

TEST_F(BscDescriptorTest, HasTheSpecifiedLayout) {
  const BscOptions options;
  EXPECT_EQ(options.NumBits(), 441);
  EXPECT_EQ(options.NumWords(), 7);
  ASSERT_GT(features_.size(), 30u);
  for (const BscFeature& f : features_) {
    ASSERT_FALSE(f.variants.empty());
    EXPECT_EQ(f.variants[0].size(), 7u);
    EXPECT_EQ(f.variants[0][6] >> (441 - 384), 0u) << "bits beyond 441 must stay zero";
    EXPECT_NEAR(f.cloud_from_lrf.determinant(), 1.0, 1e-9);  // right-handed frame
  }
}

TEST_F(BscDescriptorTest, InvariantToARigidTransform) {
  const Eigen::Isometry3d moved_from_cloud =
      Eigen::Translation3d(4.0, -7.0, 1.5) *
      Eigen::AngleAxisd(2.1, Eigen::Vector3d(0.3, -0.8, 0.5).normalized());
  PointCloud moved = cloud_;
  for (Eigen::Vector3d& p : moved.points) p = moved_from_cloud * p;
  const std::vector<BscFeature> moved_features =
      Describe(moved, keypoints_, moved_from_cloud * viewpoint_);
  ASSERT_EQ(moved_features.size(), features_.size());
  const double same = MeanDistance(features_, moved_features, 0);
  const double unrelated = MeanDistance(features_, moved_features, 7);
  std::cout << "mean Hamming distance: same keypoint after a rigid motion " << same
            << ", unrelated keypoints " << unrelated << " (of 441 bits)" << std::endl;
  EXPECT_LT(same,
            0.02 * 441);  // only floating-point ties at cell borders may flip
  EXPECT_GT(unrelated, 15 * std::max(same, 1.0));
}

TEST_F(BscDescriptorTest, RobustToNoiseAndResampling) {
  // Another random sampling of the same room with 1 cm noise, described at the nearest points.
  const PointCloud noisy = VoxelDownsample(testing::SyntheticRoom(600, 22, 0.01), 0.1);
  const KdTree3 tree(noisy.points);
  std::vector<size_t> nearest;
  for (size_t index : keypoints_) {
    size_t k;
    double squared;
    tree.Nearest(cloud_.points[index], &k, &squared);
    nearest.push_back(k);
  }
  const std::vector<BscFeature> noisy_features = Describe(noisy, nearest, viewpoint_);
  ASSERT_EQ(noisy_features.size(), features_.size());
  const double same = MeanDistance(features_, noisy_features, 0);
  const double unrelated = MeanDistance(features_, noisy_features, 7);
  std::cout << "mean Hamming distance with 1 cm noise and resampling: corresponding " << same
            << ", unrelated " << unrelated << std::endl;
  EXPECT_LT(same, 0.6 * unrelated);
}

}  // namespace
}  // namespace colmap_lidar
