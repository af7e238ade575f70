// A seeded perturbation of a pose: the rough cam_from_lidar guess that the simulator and import_kitti
// write into rig.json when asked, and the perturbed starts of tests.
#pragma once

#include "colmap/geometry/rigid3.h"

#include <cstdint>

namespace colmap_lidar {

// `truth` rotated by `rotation_deg` about a random axis (applied on the left) and shifted by
// `translation_m` in a random direction; the same seed gives the same perturbation.
colmap::Rigid3d PerturbPose(const colmap::Rigid3d& truth,
                            double rotation_deg,
                            double translation_m,
                            uint64_t seed);

}  // namespace colmap_lidar
