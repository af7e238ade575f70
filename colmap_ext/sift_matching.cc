#include "colmap_ext/sift_matching.h"

#include "colmap_ext/logging.h"
#include "lidar/util/parallel_for_each.h"

#include "colmap/scene/database.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>

namespace colmap_lidar {
namespace {

// COLMAP's descriptors are unit vectors scaled to 512: a dot product over 512^2 is a cosine.
constexpr float kDotToCosine = 1.0f / (512.0f * 512.0f);
// Rows of the first image per matrix product: 512 x 8192 floats, 16 MiB.
constexpr int kRowBlock = 512;
// Pairs whose descriptors are held at once.
constexpr size_t kPairBlock = 256;

// The nearest and second-nearest neighbour so far (largest dot products; the lowest index wins a
// tie, so that the result does not depend on the order of blocks).
struct TwoNearest {
  int index = -1;
  float best = -1e30f;
  float second = -1e30f;

  void Offer(float dot, int i) {
    if (dot > best) {
      second = best;
      best = dot;
      index = i;
    } else if (dot > second) {
      second = dot;
    }
  }
};

float Angle(float dot) { return std::acos(std::clamp(dot * kDotToCosine, -1.0f, 1.0f)); }

// COLMAP's tests of a nearest neighbour: its angle at most max_distance, and below max_ratio of
// the second nearest's.
bool Passes(const TwoNearest& nearest, const colmap::SiftMatchingOptions& options) {
  if (nearest.index < 0) return false;
  const float best = Angle(nearest.best);
  if (best > options.max_distance) return false;
  const float second = nearest.second > -1e29f ? Angle(nearest.second) : static_cast<float>(M_PI);
  return best < options.max_ratio * second;
}

SiftDescriptorsFloat ReadFloatDescriptors(const colmap::Database& database, colmap::image_t id) {
  return database.ReadDescriptors(id).cast<float>();
}

}  // namespace

colmap::FeatureMatches MatchSiftDescriptors(const SiftDescriptorsFloat& descriptors1,
                                            const SiftDescriptorsFloat& descriptors2,
                                            const colmap::SiftMatchingOptions& options) {
  const int n1 = static_cast<int>(descriptors1.rows()), n2 = static_cast<int>(descriptors2.rows());
  if (n1 == 0 || n2 == 0) return {};  // an image without features (its descriptors may be 0 x 0)
  THROW_CHECK_EQ(descriptors1.cols(), descriptors2.cols()) << "descriptors of different lengths";
  std::vector<TwoNearest> rows(n1), columns(n2);
  SiftDescriptorsFloat dots;
  for (int r0 = 0; r0 < n1; r0 += kRowBlock) {
    const int num_rows = std::min(kRowBlock, n1 - r0);
    dots.noalias() = descriptors1.middleRows(r0, num_rows) * descriptors2.transpose();
    for (int i = 0; i < num_rows; ++i) {
      const float* row = dots.row(i).data();
      for (int j = 0; j < n2; ++j) {
        rows[r0 + i].Offer(row[j], j);
        columns[j].Offer(row[j], r0 + i);
      }
    }
  }
  colmap::FeatureMatches matches;
  for (int i = 0; i < n1; ++i) {
    if (!Passes(rows[i], options)) continue;
    const int j = rows[i].index;
    if (options.cross_check && (columns[j].index != i || !Passes(columns[j], options))) continue;
    matches.emplace_back(i, j);
    if (static_cast<int>(matches.size()) == options.max_num_matches) break;
  }
  return matches;
}

void MatchImagePairs(const std::vector<std::pair<colmap::image_t, colmap::image_t>>& pairs,
                     const colmap::SiftMatchingOptions& options,
                     int min_num_matches,
                     const std::string& database_path) {
  colmap::Database database(database_path);
  for (size_t begin = 0; begin < pairs.size(); begin += kPairBlock) {
    const size_t end = std::min(pairs.size(), begin + kPairBlock);
    std::map<colmap::image_t, SiftDescriptorsFloat> descriptors;
    for (size_t k = begin; k < end; ++k) {
      for (const colmap::image_t id : {pairs[k].first, pairs[k].second}) {
        if (descriptors.count(id) == 0) descriptors[id] = ReadFloatDescriptors(database, id);
      }
    }
    std::vector<colmap::FeatureMatches> matches(end - begin);
    ParallelForEach(
        static_cast<int>(end - begin),
        [&](int k) {
          const auto& [id1, id2] = pairs[begin + k];
          matches[k] = MatchSiftDescriptors(descriptors.at(id1), descriptors.at(id2), options);
          if (static_cast<int>(matches[k].size()) < min_num_matches) matches[k].clear();
        },
        options.num_threads);
    colmap::DatabaseTransaction transaction(&database);
    for (size_t k = begin; k < end; ++k) {
      database.WriteMatches(pairs[k].first, pairs[k].second, matches[k - begin]);
    }
    std::cout << "SIFT matching: " << end << " of " << pairs.size() << " image pairs" << std::endl;
  }
}

}  // namespace colmap_lidar
