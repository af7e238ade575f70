#include "bridge/exe/simulator_commands.h"

#include "bridge/exe/command_options.h"
#include "bridge/simulation/simulate_dataset.h"

#include <iostream>

namespace colmap_lidar {

int RunSimulateDataset(int argc, char** argv) {
  sim::SimulationOptions options;
  int seed = 0;
  int lidar_points = static_cast<int>(options.lidar_points);
  CommandOptions manager;
  manager.AddRequiredOption("output_path", &options.output_path);
  manager.AddDefaultOption("scene",
                           &options.scene,
                           "t_specimen | square_pillar | cylinder_pillar | bridge_pier | street");
  manager.AddDefaultOption("num_stations", &options.num_stations);
  manager.AddChoiceOption("motion", &options.motion, sim::kMotionNames);
  manager.AddDefaultOption(
      "sweep_motion", &options.sweep_motion, "drive: the pod moves during each sweep");
  manager.AddDefaultOption(
      "moving_cars", &options.moving_cars, "drive: the street's two cars move between frames");
  manager.AddDefaultOption(
      "image_scale", &options.image_scale, "1 = 1028x752 per camera, 4 = 4112x3008");
  manager.AddChoiceOption("layout",
                          &options.layout,
                          sim::kDatasetLayoutNames,
                          "kitti: KITTI raw's folders and calibration files");
  manager.AddDefaultOption(
      "mono", &options.mono, "one camera: no right images, no 'right' in rig.json");
  manager.AddDefaultOption("lidar_points", &lidar_points, "LiDAR rays per station");
  manager.AddDefaultOption("range_noise_m", &options.range_noise_m);
  manager.AddDefaultOption("pixel_noise", &options.pixel_noise, "grey levels");
  manager.AddDefaultOption("vignetting", &options.vignetting);
  manager.AddDefaultOption("pixel_samples",
                           &options.pixel_samples,
                           "rays per pixel along each axis (N x N jittered over the pixel's area)");
  manager.AddDefaultOption("mixed_edge_points", &options.mixed_edge_points);
  manager.AddDefaultOption("guess_rotation_deg", &options.guess_rotation_deg);
  manager.AddDefaultOption("guess_translation_m", &options.guess_translation_m);
  manager.AddDefaultOption(
      "write_guess", &options.write_guess, "write cam_from_lidar_guess into rig.json");
  manager.AddDefaultOption("surface_spacing_m", &options.surface_spacing_m);
  manager.AddDefaultOption("seed", &seed);
  manager.AddDefaultOption("overwrite", &options.overwrite);
  manager.Parse(argc, argv);
  options.seed = static_cast<uint64_t>(seed);
  options.lidar_points = static_cast<size_t>(std::max(0, lidar_points));
  const sim::SimulationResult result = sim::SimulateDataset(options);
  std::cout << "simulate_dataset: wrote " << result.num_stations << " stations of scene "
            << options.scene << " to " << options.output_path << " (" << result.num_lidar_points
            << " LiDAR points, " << result.num_surface_points << " surface samples) in "
            << result.seconds << " s" << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace colmap_lidar
