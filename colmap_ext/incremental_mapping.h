// COLMAP's own incremental mapper on a database, in process: the up-to-scale model that a monocular
// dataset starts from (the same as `colmap mapper` with the rig's intrinsics held fixed).
#pragma once

#include "colmap/scene/reconstruction.h"

#include <string>

namespace colmap_lidar {

struct IncrementalMappingOptions {
  // Smallest model COLMAP keeps (its default, 10, drops short sequences).
  int min_model_size = 3;
  // The rig is calibrated: intrinsics are held.
  bool refine_intrinsics = false;

  bool Check() const;
};

// Runs IncrementalMapperController over every image of the database and returns the model with the
// most registered images (COLMAP may split a sequence into several). Throws if COLMAP builds none.
colmap::Reconstruction MapWithColmap(const std::string& database_path,
                                     const std::string& image_path,
                                     const IncrementalMappingOptions& options);

}  // namespace colmap_lidar
