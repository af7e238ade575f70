// Order statistics shared by the LiDAR library, the bridge, the commands and the tests (colmap_ext has
// COLMAP's own colmap::Median). Both take their values by copy and reorder the copy.
#pragma once

#include <vector>

namespace colmap_lidar {

// The middle value; the mean of the two middle ones for an even count; NaN for none.
double Median(std::vector<double> values);

// The value of rank round(q (n - 1)) in ascending order, q in [0, 1] (clamped); NaN for none.
double Quantile(std::vector<double> values, double q);

}  // namespace colmap_lidar
