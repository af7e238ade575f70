// COLMAP's Options::Check() convention in lidar/ (which never includes COLMAP): inside Check(),
// LIDAR_CHECK_OPTION*(...) prints "Check failed: <condition>" with the file and line to stderr and
// returns false, like COLMAP's CHECK_OPTION*; an entry point calls ThrowUnlessValid(options, "Name"),
// like COLMAP's THROW_CHECK(options.Check()), so a bad option is one std::invalid_argument. A NaN
// fails every comparison.
#pragma once

#include <stdexcept>
#include <string>

namespace colmap_lidar {
namespace internal {
void ReportFailedOption(const char* condition, const char* file, int line);
}  // namespace internal

#define LIDAR_CHECK_OPTION(condition)                                               \
  do {                                                                              \
    if (!(condition)) {                                                             \
      ::colmap_lidar::internal::ReportFailedOption(#condition, __FILE__, __LINE__); \
      return false;                                                                 \
    }                                                                               \
  } while (false)
#define LIDAR_CHECK_OPTION_GT(a, b) LIDAR_CHECK_OPTION((a) > (b))
#define LIDAR_CHECK_OPTION_GE(a, b) LIDAR_CHECK_OPTION((a) >= (b))
#define LIDAR_CHECK_OPTION_LT(a, b) LIDAR_CHECK_OPTION((a) < (b))
#define LIDAR_CHECK_OPTION_LE(a, b) LIDAR_CHECK_OPTION((a) <= (b))

// Throws std::invalid_argument("<name>: invalid options ...") unless options.Check().
template <typename Options>
void ThrowUnlessValid(const Options& options, const std::string& name) {
  if (!options.Check()) {
    throw std::invalid_argument(name + ": invalid options (the failed check is printed above)");
  }
}

}  // namespace colmap_lidar
