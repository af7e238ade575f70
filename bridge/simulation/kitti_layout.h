// A simulated capture written in KITTI raw's exact layout (simulate_dataset --layout kitti), so that
// `import_kitti` is tested on data whose truth is known:
//   ROOT/drive/image_02/data/%010d.png (image_03 for a stereo rig), velodyne_points/data/%010d.bin
//   (float32 x y z reflectance), ROOT/calibration/calib_cam_to_cam.txt and calib_velo_to_cam.txt in the
//   published text format (colmap_ext/kitti_calibration.h), ROOT/ground_truth/ as the simulator writes
//   it (cam_from_world.txt keyed by frame name, cam_from_lidar.txt of camera 2, surface.ply).
// The calibration is chosen so that KITTI's formula gives back the simulator's truth exactly:
// P_rect_0X = K [I | o_X] with o_2 a few centimetres like KITTI's, o_3 = o_2 + right_from_left's
// translation, a generic R_rect_00, and [R|T] = inverse([I | o_2] R_rect_00) cam_from_lidar.
#pragma once

#include <string>

namespace colmap_lidar {
namespace sim {

// Converts the station dataset at `dataset_path` (the simulator's output; a stereo rig's right camera
// must be rectified: identity rotation) into KITTI's layout at `kitti_root`.
void WriteKittiLayout(const std::string& dataset_path, const std::string& kitti_root);

}  // namespace sim
}  // namespace colmap_lidar
