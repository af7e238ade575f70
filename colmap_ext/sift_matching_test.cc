#include "colmap_ext/sift_matching.h"

#include "tests/testing/feature_matches.h"
#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/database.h"
#include "colmap/sensor/models.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace colmap_lidar {
namespace {

// Non-negative unit vectors scaled to 512 and rounded to bytes, as COLMAP stores SIFT descriptors.
colmap::FeatureDescriptors RandomDescriptors(int n, std::mt19937* random) {
  std::gamma_distribution<double> magnitude(0.5, 1.0);
  colmap::FeatureDescriptors descriptors(n, 128);
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd v(128);
    for (int k = 0; k < 128; ++k) v[k] = magnitude(*random);
    v *= 512 / v.norm();
    for (int k = 0; k < 128; ++k) descriptors(i, k) = static_cast<uint8_t>(std::min(255.0, v[k]));
  }
  return descriptors;
}

// The second image: the first's features in another order, each byte moved by up to `noise`, and
// `num_new` features of its own.
colmap::FeatureDescriptors Shuffled(const colmap::FeatureDescriptors& first,
                                    const std::vector<int>& order,
                                    int noise,
                                    int num_new,
                                    std::mt19937* random) {
  std::uniform_int_distribution<int> step(-noise, noise);
  colmap::FeatureDescriptors second(order.size() + num_new, 128);
  for (size_t j = 0; j < order.size(); ++j) {
    for (int k = 0; k < 128; ++k) {
      second(j, k) = static_cast<uint8_t>(std::clamp(first(order[j], k) + step(*random), 0, 255));
    }
  }
  second.bottomRows(num_new) = RandomDescriptors(num_new, random);
  return second;
}

// COLMAP's tests written out directly: integer dot products, angles in double precision.
colmap::FeatureMatches ReferenceMatches(const colmap::FeatureDescriptors& a,
                                        const colmap::FeatureDescriptors& b,
                                        const colmap::SiftMatchingOptions& options) {
  const auto nearest = [&](const colmap::FeatureDescriptors& from,
                           const colmap::FeatureDescriptors& to,
                           int i) -> int {
    int64_t best = -1, second = -1;
    int index = -1;
    for (int j = 0; j < to.rows(); ++j) {
      const int64_t dot = from.row(i).cast<int64_t>().dot(to.row(j).cast<int64_t>());
      if (dot > best) {
        second = best;
        best = dot;
        index = j;
      } else if (dot > second) {
        second = dot;
      }
    }
    const auto angle = [](int64_t dot) {
      return std::acos(std::clamp(dot / (512.0 * 512.0), -1.0, 1.0));
    };
    const double best_angle = angle(best), second_angle = second < 0 ? M_PI : angle(second);
    if (best_angle > options.max_distance || best_angle >= options.max_ratio * second_angle) {
      return -1;
    }
    return index;
  };
  colmap::FeatureMatches matches;
  for (int i = 0; i < a.rows(); ++i) {
    const int j = nearest(a, b, i);
    if (j >= 0 && (!options.cross_check || nearest(b, a, j) == i)) matches.emplace_back(i, j);
  }
  return matches;
}

// 1300 features: three blocks of the matrix product, the last one partial.
TEST(SiftMatchingTest, SameMatchesAsCOLMAPsTestsOnExactDotProducts) {
  std::mt19937 random(3);
  const colmap::FeatureDescriptors first = RandomDescriptors(1300, &random);
  std::vector<int> order(1000);
  std::iota(order.begin(), order.end(), 200);
  std::shuffle(order.begin(), order.end(), random);
  const colmap::FeatureDescriptors second = Shuffled(first, order, 6, 400, &random);
  for (const bool cross_check : {true, false}) {
    colmap::SiftMatchingOptions options;
    options.cross_check = cross_check;
    const colmap::FeatureMatches matches =
        MatchSiftDescriptors(first.cast<float>(), second.cast<float>(), options);
    EXPECT_TRUE(testing::SameMatches(matches, ReferenceMatches(first, second, options)));
    // The 1000 shared features are found (a few may fail the ratio test), nothing else.
    EXPECT_GT(matches.size(), 950u);
    int wrong = 0;
    for (const colmap::FeatureMatch& match : matches) {
      wrong += match.point2D_idx2 >= order.size() ||
               order[match.point2D_idx2] != static_cast<int>(match.point2D_idx1);
    }
    EXPECT_EQ(wrong, 0);
  }
}

TEST(SiftMatchingTest, AnAmbiguousFeatureFailsTheRatioTest) {
  std::mt19937 random(5);
  const colmap::FeatureDescriptors first = RandomDescriptors(1, &random);
  colmap::FeatureDescriptors second(2, 128);
  second.row(0) = first.row(0);
  second.row(1) = first.row(0);
  second(1, 0) = static_cast<uint8_t>(std::min(255, first(0, 0) + 1));
  const colmap::SiftMatchingOptions options;
  EXPECT_TRUE(MatchSiftDescriptors(first.cast<float>(), second.cast<float>(), options).empty());
  EXPECT_EQ(
      MatchSiftDescriptors(first.cast<float>(), second.topRows(1).cast<float>(), options).size(),
      1u);
}

TEST(SiftMatchingTest, AnImageWithoutFeaturesHasNoMatches) {
  std::mt19937 random(7);
  const SiftDescriptorsFloat some = RandomDescriptors(20, &random).cast<float>();
  const colmap::SiftMatchingOptions options;
  EXPECT_TRUE(MatchSiftDescriptors(some, SiftDescriptorsFloat(0, 0), options).empty());
  EXPECT_TRUE(MatchSiftDescriptors(SiftDescriptorsFloat(0, 128), some, options).empty());
  EXPECT_THROW(MatchSiftDescriptors(some, SiftDescriptorsFloat::Zero(3, 64), options),
               std::exception);
}

TEST(SiftMatchingTest, WritesEachPairsMatchesAndNoneBelowTheMinimum) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("database.db");
  std::mt19937 random(9);
  std::vector<colmap::image_t> ids;
  {
    colmap::Database database(path);
    const colmap::camera_t camera = database.WriteCamera(
        colmap::Camera::CreateFromModelName(colmap::kInvalidCameraId, "PINHOLE", 500, 640, 480));
    const colmap::FeatureDescriptors shared = RandomDescriptors(300, &random);
    std::vector<int> first_half(150);
    std::iota(first_half.begin(), first_half.end(), 0);
    const std::vector<colmap::FeatureDescriptors> descriptors = {
        shared, Shuffled(shared, first_half, 4, 50, &random), RandomDescriptors(200, &random)};
    for (size_t i = 0; i < descriptors.size(); ++i) {
      colmap::Image image;
      image.SetName(std::to_string(i) + ".png");
      image.SetCameraId(camera);
      ids.push_back(database.WriteImage(image));
      database.WriteKeypoints(ids.back(), colmap::FeatureKeypoints(descriptors[i].rows()));
      database.WriteDescriptors(ids.back(), descriptors[i]);
    }
  }
  colmap::SiftMatchingOptions options;
  options.num_threads = 2;
  MatchImagePairs({{ids[0], ids[1]}, {ids[0], ids[2]}, {ids[1], ids[2]}}, options, 15, path);
  const colmap::Database database(path);
  EXPECT_GT(database.ReadMatches(ids[0], ids[1]).size(), 140u);
  EXPECT_TRUE(database.ExistsMatches(ids[0], ids[2]));  // written, and empty
  EXPECT_TRUE(database.ReadMatches(ids[0], ids[2]).empty());
  EXPECT_TRUE(database.ReadMatches(ids[1], ids[2]).empty());
}

}  // namespace
}  // namespace colmap_lidar
