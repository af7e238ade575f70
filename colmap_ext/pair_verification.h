// Geometric verification of matched image pairs that gives the same two-view geometries for any
// thread count. COLMAP's matcher verifies pairs on a pool of threads whose RANSAC draws from one
// random generator per thread, so which pair gets which draws depends on scheduling; here each pair
// runs COLMAP's own two-view estimation (EstimateTwoViewGeometry) with the generator seeded from
// the pair's id, and the result replaces the matcher's.
#pragma once

#include "colmap/estimators/two_view_geometry.h"
#include "colmap/util/types.h"

#include <set>
#include <string>

namespace colmap_lidar {

// The ids of the image pairs that have a two-view geometry in the database.
std::set<colmap::image_pair_t> VerifiedPairIds(const std::string& database_path);

// Re-verifies every pair with raw matches whose id is not in `keep` (pairs verified before this
// import, e.g. by the user's own matcher, keep their geometry) and writes its two-view geometry in
// one transaction. A pair with fewer inliers than options.min_num_inliers gets an empty geometry,
// as COLMAP's matcher writes it. Returns the number of pairs re-verified.
size_t VerifyPairsDeterministically(const colmap::TwoViewGeometryOptions& options,
                                    const std::set<colmap::image_pair_t>& keep,
                                    const std::string& database_path,
                                    int num_threads);

}  // namespace colmap_lidar
