// SIFT descriptor matching that gives the same matches for any thread count: exact nearest
// neighbours by the descriptors' dot products, computed as single-precision matrix products in
// blocks (exact: COLMAP's descriptors are bytes whose products sum to less than 2^24), with
// COLMAP's tests on the angle between descriptors (SiftMatchingOptions: max_distance, max_ratio to
// the second nearest, cross_check, max_num_matches). COLMAP's own CPU matcher draws its FLANN trees
// from the process-wide std::rand that its matcher threads share, so its matches change from run to
// run; its brute-force matcher is exact but takes seconds per pair of 6000 features.
#pragma once

#include "colmap/feature/sift.h"
#include "colmap/feature/types.h"
#include "colmap/util/types.h"

#include <Eigen/Core>

#include <string>
#include <utility>
#include <vector>

namespace colmap_lidar {

// One image's descriptors as floats, one row per feature.
using SiftDescriptorsFloat = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The matches between two images' descriptors, by index of the first image's features.
colmap::FeatureMatches MatchSiftDescriptors(const SiftDescriptorsFloat& descriptors1,
                                            const SiftDescriptorsFloat& descriptors2,
                                            const colmap::SiftMatchingOptions& options);

// Matches every pair (image ids) and writes its raw matches into the database, pairs with fewer
// than `min_num_matches` getting none (as COLMAP's matcher writes them). Pairs run in parallel on
// `num_threads` (<= 0: all cores); each image's descriptors are read once per block of pairs.
void MatchImagePairs(const std::vector<std::pair<colmap::image_t, colmap::image_t>>& pairs,
                     const colmap::SiftMatchingOptions& options,
                     int min_num_matches,
                     const std::string& database_path);

}  // namespace colmap_lidar
