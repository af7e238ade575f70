// Landmarks by COLMAP's own triangulator at fixed poses: the tracks (which keypoints observe one
// landmark) are built from the database's verified matches at the given poses, as COLMAP's mapper
// builds them (IncrementalMapperController::TriangulateReconstruction: triangulation, track merging
// and completion, retriangulation, bundle adjustment of the landmarks alone, filtering). The pose
// initialiser builds the initial model this way; the joint step rebuilds the tracks at its adjusted
// poses, since tracks built at rough start poses split and merge observations differently and the
// joint, which only adjusts, would keep the start's partition.
#pragma once

#include "colmap/scene/reconstruction.h"

#include <map>
#include <memory>
#include <string>

namespace colmap_lidar {

// A model holding `cameras`, the images of `cam_from_world` (registered, at those poses) and the
// landmarks COLMAP triangulates for them from the database at `database_path`. Images without any
// verified match join after the triangulation, without landmarks.
std::shared_ptr<colmap::Reconstruction> TriangulateAtPoses(
    const std::string& database_path,
    const std::map<colmap::camera_t, colmap::Camera>& cameras,
    const std::map<colmap::image_t, colmap::Rigid3d>& cam_from_world);

// The same for the registered images of `reconstruction`, at its poses and with its cameras: its
// landmarks are replaced by newly triangulated tracks.
void RetriangulateTracks(const std::string& database_path, colmap::Reconstruction* reconstruction);

// The fraction of `before`'s landmark observations whose track `after` does not hold as it is: an
// observation counts when its track lost, gained or split observations or vanished (0: the same
// tracks, wherever their landmarks lie).
double FractionOfObservationsRetracked(const colmap::Reconstruction& before,
                                       const colmap::Reconstruction& after);

}  // namespace colmap_lidar
