// Consistency of the two kinds of pose-graph edges: a LiDAR edge and the image edges between the same
// two stations measure one motion of the sensor pod, so their rotation angles agree whatever
// cam_from_lidar is (A = X B X^-1 has B's angle). A LiDAR edge that disagrees by tens of degrees is a
// wrong registration (sparse clouds: ICP slid along the ground plane); the check needs no extrinsic,
// so it runs before the hand-eye.
#pragma once

#include "colmap/geometry/rigid3.h"
#include "colmap/util/types.h"

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace colmap_lidar {

// Image edges of A_c: cam_i_from_cam_j by (image_i, image_j).
using ImageEdges = std::map<std::pair<colmap::image_t, colmap::image_t>, colmap::Rigid3d>;

// An edge of A_l between the stations of two images.
struct LidarStationEdge {
  colmap::image_t image_i = 0, image_j = 0;
  colmap::Rigid3d lidar_i_from_lidar_j;
  double weight = 0;  // inliers
};

// The LiDAR edges that the images do not contradict. The image motion between the two stations is
// the image edge's own or, when image edges connect the stations otherwise, the chain of image edges'
// (breadth first from each connected component's first station); a LiDAR edge whose rotation angle
// differs from it by more than max_angle_deg (plus 0.25 deg per chained edge) is left out and described
// in `contradicted` ("name_i name_j: LiDAR x deg, images y deg"). Edges between stations that no image
// edges connect are kept: there the LiDAR bridges the images.
std::vector<LidarStationEdge> DropContradictedLidarEdges(
    const ImageEdges& image_edges,
    const std::vector<LidarStationEdge>& lidar_edges,
    const std::map<colmap::image_t, std::string>& names,
    double max_angle_deg,
    std::vector<std::string>* contradicted);

}  // namespace colmap_lidar
