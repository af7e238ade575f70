// Per-station parallel loops: one item per OpenMP thread, exceptions carried out of the parallel
// region (an exception must not leave an OpenMP region) and rethrown after every item ran. Sums over
// many items in fixed chunks, so that the result does not depend on the number of threads.
#pragma once

#include <functional>
#include <vector>

namespace colmap_lidar {

// Runs fn(i) for every i in [0, n), items in parallel on `num_threads` OpenMP threads (<= 0: all
// cores); OpenMP regions inside fn run on their thread alone. When items throw, the exception of the
// lowest i is rethrown once all items have run.
void ParallelForEach(int n, const std::function<void(int)>& fn, int num_threads = 0);

// The sum over i in [0, n) of what add(i, &sum) accumulates into a default-constructed Sum, with
// Sum::Add(const Sum&) combining two. The items are split into a fixed number of chunks whatever the
// thread count, each chunk summed in order and the chunks combined in order: the same bits with one
// thread or many (a floating-point sum depends on its order).
template <typename Sum, typename AddItem>
Sum ChunkedSum(long n, const AddItem& add) {
  constexpr long kNumChunks = 64;
  std::vector<Sum> chunks(kNumChunks);
#pragma omp parallel for schedule(dynamic)
  for (long c = 0; c < kNumChunks; ++c) {
    for (long i = c * n / kNumChunks; i < (c + 1) * n / kNumChunks; ++i) add(i, &chunks[c]);
  }
  Sum total;
  for (const Sum& chunk : chunks) total.Add(chunk);
  return total;
}

}  // namespace colmap_lidar
