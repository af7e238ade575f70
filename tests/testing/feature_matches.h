// Whether two lists of COLMAP feature matches pair the same features in the same order.
#pragma once

#include "colmap/feature/types.h"

namespace colmap_lidar {
namespace testing {

inline bool SameMatches(const colmap::FeatureMatches& a, const colmap::FeatureMatches& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].point2D_idx1 != b[i].point2D_idx1 || a[i].point2D_idx2 != b[i].point2D_idx2) {
      return false;
    }
  }
  return true;
}

}  // namespace testing
}  // namespace colmap_lidar
