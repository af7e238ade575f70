// The simulator's CLI command (linked into the colmap-lidar executable only).
#pragma once

namespace colmap_lidar {

// colmap-lidar simulate_dataset --scene NAME --output_path DATASET [options]
int RunSimulateDataset(int argc, char** argv);

}  // namespace colmap_lidar
