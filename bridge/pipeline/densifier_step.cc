#include "bridge/pipeline/densifier_step.h"

#include "colmap_ext/logging.h"

#include "colmap/scene/reconstruction.h"

#include <filesystem>
#include <iomanip>
#include <iostream>

namespace colmap_lidar {

void RunDensifierStep(const StationDataset& dataset,
                      const DensifierPaths& paths,
                      const DensifierOptions& options) {
  THROW_CHECK(options.Check());
  const std::string cam_from_lidar_path =
      paths.cam_from_lidar_path.empty()
          ? (std::filesystem::path(paths.input_path) / "cam_from_lidar.txt").string()
          : paths.cam_from_lidar_path;
  const colmap::Rigid3d cam_from_lidar = ReadPoseFile(cam_from_lidar_path);
  THROW_CHECK(std::filesystem::is_directory(paths.input_path))
      << "No sparse model at " << paths.input_path;
  colmap::Reconstruction reconstruction;
  reconstruction.Read(paths.input_path);
  const DensifierSummary summary = Densify(
      reconstruction, cam_from_lidar, dataset, paths.depth_path, paths.output_path, options);
  size_t removed = 0, filled = 0, stereo = 0;
  for (const StationDensification& station : summary.stations) {
    removed += station.refinement.stereo_removed;
    filled += station.refinement.filled;
    stereo += station.refinement.stereo_pixels;
  }
  std::cout << std::fixed << std::setprecision(1) << "densifier: " << summary.stations.size()
            << " stations in " << summary.seconds << " s; stereo pixels " << stereo << ", removed "
            << removed << ", filled " << filled << "; " << summary.fused_points << " points in "
            << paths.output_path << "/fused.ply, " << summary.lidar_map_points
            << " in lidar_map.ply; COLMAP dense workspace in " << paths.output_path << std::endl;
}

}  // namespace colmap_lidar
