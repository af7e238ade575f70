#include "bridge/densifier.h"
#include "bridge/exe/commands.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/station_dataset.h"

#include "colmap/controllers/option_manager.h"

#include <filesystem>
#include <iomanip>
#include <iostream>

namespace colmap_lidar {

int RunDensifier(int argc, char** argv) {
  std::string input_path, dataset_path, depth_path, output_path, cam_from_lidar_path;
  DensifierOptions densifier;
  LidarDepthRefinementOptions& refinement = densifier.refinement;
  colmap::OptionManager options;
  options.AddRequiredOption("input_path", &input_path, "refined sparse model (joint_adjuster)");
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddRequiredOption("depth_path", &depth_path, "stereo_depth's output folder");
  options.AddRequiredOption("output_path", &output_path);
  options.AddDefaultOption("cam_from_lidar",
                           &cam_from_lidar_path,
                           "qw qx qy qz tx ty tz file; default "
                           "INPUT/cam_from_lidar.txt");
  options.AddDefaultOption("refine_with_lidar",
                           &densifier.refine_with_lidar,
                           "0: fuse the stereo depth maps as they are");
  options.AddDefaultOption("lidar_sample_spacing_m", &densifier.surface.sample_spacing_m);
  options.AddDefaultOption("lidar_normal_radius_m", &densifier.surface.radius_m);
  options.AddDefaultOption("window_radius_px", &refinement.window_radius_px);
  options.AddDefaultOption("remove_inconsistent", &refinement.remove_inconsistent);
  options.AddDefaultOption("max_abs_diff_m", &refinement.max_abs_diff_m);
  options.AddDefaultOption("max_rel_diff", &refinement.max_rel_diff);
  options.AddDefaultOption("max_check_curvature", &refinement.max_check_curvature);
  options.AddDefaultOption("max_unreplaceable_diff_m", &refinement.max_unreplaceable_diff_m);
  options.AddDefaultOption("plane_tolerance_m", &refinement.plane_tolerance_m);
  options.AddDefaultOption("max_normal_angle_deg", &refinement.max_normal_angle_deg);
  options.AddDefaultOption("fill_holes", &refinement.fill_holes);
  options.AddDefaultOption("min_fill_samples", &refinement.min_fill_samples);
  options.AddDefaultOption("min_fill_quadrants", &refinement.min_fill_quadrants);
  options.AddDefaultOption("max_fill_curvature", &refinement.max_fill_curvature);
  options.AddDefaultOption("max_fill_view_angle_deg", &refinement.max_fill_view_angle_deg);
  options.AddDefaultOption("min_depth_m", &densifier.min_depth_m);
  options.AddDefaultOption("max_depth_m", &densifier.max_depth_m);
  options.AddDefaultOption(
      "min_consistent_views", &densifier.min_consistent_views, "cross-station check (0 = off)");
  options.AddDefaultOption("max_neighbor_views", &densifier.max_neighbor_views);
  options.AddDefaultOption("consistency_abs_m", &densifier.consistency_abs_m);
  options.AddDefaultOption("consistency_rel", &densifier.consistency_rel);
  options.AddDefaultOption("fused_voxel_size_m", &densifier.fused_voxel_size_m);
  options.AddDefaultOption("lidar_map_voxel_size_m", &densifier.lidar_map_voxel_size_m);
  options.Parse(argc, argv);
  THROW_CHECK(densifier.Check());
  if (cam_from_lidar_path.empty()) {
    cam_from_lidar_path = (std::filesystem::path(input_path) / "cam_from_lidar.txt").string();
  }
  const StationDataset dataset = ReadStationDataset(dataset_path);
  const colmap::Rigid3d cam_from_lidar = ReadPoseFile(cam_from_lidar_path);
  THROW_CHECK(std::filesystem::is_directory(input_path)) << "No sparse model at " << input_path;
  colmap::Reconstruction reconstruction;
  reconstruction.Read(input_path);
  const DensifierSummary summary =
      Densify(reconstruction, cam_from_lidar, dataset, depth_path, output_path, densifier);
  size_t removed = 0, filled = 0, stereo = 0;
  for (const StationDensification& station : summary.stations) {
    removed += station.refinement.stereo_removed;
    filled += station.refinement.filled;
    stereo += station.refinement.stereo_pixels;
  }
  std::cout << std::fixed << std::setprecision(1) << "densifier: " << summary.stations.size()
            << " stations in " << summary.seconds << " s; stereo pixels " << stereo << ", removed "
            << removed << ", filled " << filled << "; " << summary.fused_points << " points in "
            << output_path << "/fused.ply, " << summary.lidar_map_points
            << " in lidar_map.ply; COLMAP dense "
            << "workspace in " << output_path << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
