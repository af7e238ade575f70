// COLMAP's THROW_CHECK_* and CHECK_OPTION_* macros expand to unqualified helper names that live in
// namespace colmap; this header makes them usable inside namespace colmap_lidar. Include it instead of
// colmap/util/logging.h in colmap_ext/ and bridge/ code.
#pragma once

#include "colmap/util/logging.h"

namespace colmap_lidar {
using colmap::__CheckOptionImpl;
using colmap::__CheckOptionOpImpl;
using colmap::LogMessageFatalThrow;
using colmap::LogMessageFatalThrowDefault;
}  // namespace colmap_lidar
