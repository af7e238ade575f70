// Per-station parallel loops: one item per OpenMP thread, exceptions carried out of the parallel
// region (an exception must not leave an OpenMP region) and rethrown after every item ran.
#pragma once

#include <functional>

namespace colmap_lidar {

// Runs fn(i) for every i in [0, n), items in parallel on `num_threads` OpenMP threads (<= 0: all
// cores); OpenMP regions inside fn run on their thread alone. When items throw, the exception of the
// lowest i is rethrown once all items have run.
void ParallelForEach(int n, const std::function<void(int)>& fn, int num_threads = 0);

}  // namespace colmap_lidar
