#include "colmap_ext/incremental_mapping.h"

#include "colmap_ext/logging.h"

#include "colmap/controllers/incremental_mapper.h"
#include "colmap/scene/reconstruction_manager.h"

#include <iostream>
#include <memory>
#include <stdexcept>

namespace colmap_lidar {

bool IncrementalMappingOptions::Check() const {
  CHECK_OPTION_GE(min_model_size, 2);
  return true;
}

colmap::Reconstruction MapWithColmap(const std::string& database_path,
                                     const std::string& image_path,
                                     const IncrementalMappingOptions& options) {
  THROW_CHECK(options.Check());
  auto mapper_options = std::make_shared<colmap::IncrementalMapperOptions>();
  mapper_options->min_model_size = options.min_model_size;
  mapper_options->ba_refine_focal_length = options.refine_intrinsics;
  mapper_options->ba_refine_principal_point = false;
  mapper_options->ba_refine_extra_params = options.refine_intrinsics;
  mapper_options->num_threads = -1;
  auto models = std::make_shared<colmap::ReconstructionManager>();
  colmap::IncrementalMapperController mapper(mapper_options, image_path, database_path, models);
  mapper.Run();
  if (models->Size() == 0) {
    throw std::runtime_error("COLMAP's incremental mapper built no model from " + database_path +
                             " (too few matches between the images?)");
  }
  size_t best = 0;
  for (size_t k = 1; k < models->Size(); ++k) {
    if (models->Get(k)->NumRegImages() > models->Get(best)->NumRegImages()) best = k;
  }
  std::cout << "COLMAP mapper: " << models->Size() << " model(s); the largest has "
            << models->Get(best)->NumRegImages() << " registered images and "
            << models->Get(best)->NumPoints3D() << " points" << std::endl;
  return *models->Get(best);
}

}  // namespace colmap_lidar
