#include "lidar/util/parallel_for_each.h"

#include <omp.h>

#include <exception>
#include <vector>

namespace colmap_lidar {

void ParallelForEach(int n, const std::function<void(int)>& fn, int num_threads) {
  if (n <= 0) return;
  std::vector<std::exception_ptr> errors(n);
  const int threads = num_threads > 0 ? num_threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic) num_threads(threads)
  for (int i = 0; i < n; ++i) {
    try {
      fn(i);
    } catch (...) {
      errors[i] = std::current_exception();
    }
  }
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace colmap_lidar
