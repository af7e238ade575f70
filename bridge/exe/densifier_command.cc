// colmap-lidar densifier: the dense model of a refined sparse model (bridge/dense/densifier.h).
#include "bridge/exe/commands.h"
#include "bridge/exe/steps.h"
#include "bridge/initialization/lidar_registration_files.h"
#include "colmap_ext/logging.h"

namespace colmap_lidar {

void AddDensifierOptions(const std::string& prefix,
                         CommandOptions* manager,
                         DensifierOptions* options) {
  PrefixedOptions add(manager, prefix);
  LidarDepthRefinementOptions& refinement = options->refinement;
  add.Add("refine_with_lidar",
          &options->refine_with_lidar,
          "0: fuse the stereo depth maps as they are");
  add.Add("lidar_sample_spacing_m", &options->surface.sample_spacing_m);
  add.Add("lidar_normal_radius_m", &options->surface.radius_m);
  add.Add(
      "lidar_grow_sparse_neighbourhoods",
      &options->surface.grow_sparse_neighbourhoods,
      "a LiDAR sample with too few neighbours within the normal radius grows its own instead of "
      "being dropped (always on without stereo depth)");
  add.Add("window_radius_px", &refinement.window_radius_px);
  add.Add("remove_inconsistent", &refinement.remove_inconsistent);
  add.Add("max_abs_diff_m", &refinement.max_abs_diff_m);
  add.Add("max_rel_diff", &refinement.max_rel_diff);
  add.Add("max_check_curvature", &refinement.max_check_curvature);
  add.Add("max_unreplaceable_diff_m", &refinement.max_unreplaceable_diff_m);
  add.Add("plane_tolerance_m", &refinement.plane_tolerance_m);
  add.Add("max_normal_angle_deg", &refinement.max_normal_angle_deg);
  add.Add("fill_holes", &refinement.fill_holes);
  add.Add("min_fill_samples", &refinement.min_fill_samples);
  add.Add("min_fill_quadrants", &refinement.min_fill_quadrants);
  add.Add("max_fill_curvature", &refinement.max_fill_curvature);
  add.Add("max_fill_view_angle_deg", &refinement.max_fill_view_angle_deg);
  add.Add("min_depth_m", &options->min_depth_m);
  add.Add("max_depth_m", &options->max_depth_m);
  add.Add("min_consistent_views", &options->min_consistent_views, "cross-station check (0 = off)");
  add.Add("max_neighbor_views", &options->max_neighbor_views);
  add.Add("consistency_abs_m", &options->consistency_abs_m);
  add.Add("consistency_rel", &options->consistency_rel);
  add.Add("fused_voxel_size_m", &options->fused_voxel_size_m);
  add.Add("lidar_map_voxel_size_m", &options->lidar_map_voxel_size_m);
}

int RunDensifier(int argc, char** argv) {
  std::string dataset_path, registration_path;
  DensifierPaths paths;
  DensifierOptions densifier;
  CommandOptions options;
  options.AddRequiredOption(
      "input_path", &paths.input_path, "refined sparse model (joint_adjuster)");
  options.AddRequiredOption("dataset_path", &dataset_path);
  options.AddDefaultOption(
      "depth_path",
      &paths.depth_path,
      "stereo_depth's output folder; empty (a monocular rig): LiDAR depth only");
  options.AddRequiredOption("output_path", &paths.output_path);
  options.AddDefaultOption("cam_from_lidar",
                           &paths.cam_from_lidar_path,
                           "qw qx qy qz tx ty tz file; default INPUT/cam_from_lidar.txt");
  options.AddDefaultOption("registration_path", &registration_path, kRegistrationPathHelp);
  AddDensifierOptions("", &options, &densifier);
  options.Parse(argc, argv);
  THROW_CHECK(densifier.Check());  // before any file is read
  RunDensifierStep(
      WithRegistratorClouds(ReadStationDataset(dataset_path), registration_path), paths, densifier);
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
