// Initial station poses and cam_from_lidar for the joint problem (the initialisation of Zhen et al. 2019):
// 1. image edges A_c: metric relative poses from matches with depth priors
// (bridge/initialization/image_pair_poses.h);
// 2. LiDAR edges A_l: lidar_registrator's pairs.txt;
// 3. cam_from_lidar: rig.json's guess if present, else hand-eye over the pairs with both an image and a
//    LiDAR edge (bridge/initialization/hand_eye.h); rotation about one axis only (a car) without a
// guess: the planar    hand-eye on COLMAP's two-view geometry (rotation; translation 0, the axis named); no rotation at
//    all (a straight drive) without a guess: the travel direction and the structure
//    (bridge/initialization/travel_structure_extrinsic.h); when that fails too, an error saying
// why;
// 4. LiDAR edges become camera edges through cam_from_lidar; a maximum-weight spanning tree from the
//    first station gives initial poses; a pose graph over all edges (Ceres) refines them. Stations that
//    no edge reaches are reported and left out.
// The world frame is the first station's camera frame; units are metres.
//
// A monocular dataset has no depth priors, so no metric image edges: InitializeMonocular takes
// cam_from_lidar from the guess or a hand-eye between COLMAP's two-view rotations and translation
// directions and the LiDAR motions, and places the stations through their LiDAR poses.
#pragma once

#include "bridge/initialization/hand_eye.h"
#include "bridge/initialization/image_pair_poses.h"
#include "bridge/initialization/lidar_registration_files.h"
#include "bridge/initialization/stereo_lidar_alignment.h"
#include "bridge/initialization/travel_structure_extrinsic.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cycle_consistency.h"

#include "colmap/scene/reconstruction.h"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace colmap_lidar {

struct PoseInitializerOptions {
  ImagePairPoseOptions image_pairs;
  HandEyeOptions hand_eye;
  // The similarity hand-eye of a monocular rig: a driving platform turns by a few degrees between
  // frames, so smaller rotations give axes (weighted by their angle) and the others their translation
  // directions; a monocular model can be locally wrong, so camera and LiDAR rotation angles must agree
  // closely.
  HandEyeOptions similarity_hand_eye = [] {
    HandEyeOptions options;
    options.min_rotation_deg = 1.0;
    options.max_axis_residual_deg = 0.5;
    return options;
  }();
  // A drive that does not turn, without a guess: cam_from_lidar from the travel direction and the
  // structure both sensors see.
  TravelStructureOptions travel_structure;
  // false: hand-eye even when rig.json has a guess
  bool use_guess = true;
  // With stereo depth: the start (guess or hand-eye) refined by aligning each station's stereo depth
  // with its own LiDAR cloud (bridge/initialization/stereo_lidar_alignment.h), which needs no
  // motion.
  bool align_stereo_with_lidar = true;
  StereoLidarAlignmentOptions stereo_alignment;
  // A LiDAR edge and an image edge of the same station pair measure one motion of the pod, so their
  // rotation angles agree whatever cam_from_lidar is (A = X B X^-1); a LiDAR edge whose angle differs
  // by more than this (degrees) is a wrong registration (sparse clouds: ICP slid along the ground) and
  // is left out of the hand-eye and the pose graph. Wrong registrations differ by tens of degrees,
  // while a long chain of image edges can itself be a few degrees off.
  double max_lidar_image_angle_deg = 5.0;
  // LiDAR edges that lidar_registrator accepted as degenerate (a direction its ICP barely
  // constrains: a ground plane leaves the yaw free) enter the pose graph as full 6-DoF edges, and on
  // sparse clouds they can be wrong by up to 180 deg. They are left out unless this is set; a
  // station only they reach is then unreachable.
  bool use_degenerate_lidar_edges = false;
  // Once cam_from_lidar is chosen, image and LiDAR edges are motions of one camera: an edge that
  // breaks every cycle (3 stations, or an image and a LiDAR edge of one pair) it lies on within these
  // tolerances is left out of the pose graph (lidar/cycle_consistency.h). Wider than the LiDAR
  // graph's own (0.15 m, 1 deg): image edges from 3-point RANSAC on depth priors are coarser.
  CycleConsistencyOptions mixed_cycles = [] {
    CycleConsistencyOptions options;
    options.max_translation_m = 0.25;
    options.max_rotation_deg = 3.0;
    return options;
  }();
  // pose-graph edge weights
  double sigma_rotation_deg = 0.1;
  double sigma_translation_m = 0.005;

  bool Check() const;
};

struct PoseGraphEdge {
  colmap::image_t image_i = 0, image_j = 0;
  colmap::Rigid3d cam_i_from_cam_j;
  double weight = 0;  // inliers
  bool from_lidar = false;
};

struct PoseInitialization {
  std::map<colmap::image_t, colmap::Rigid3d> cam_from_world;  // reachable stations
  std::vector<std::string> unreachable;                       // image names
  std::map<std::string, std::string> unreachable_reason;      // image name -> why (if known)
  // Cameras that replace the database's (an existing model's refined intrinsics); empty: none.
  std::map<colmap::camera_t, colmap::Camera> cameras;
  colmap::Rigid3d cam_from_lidar;
  std::string extrinsic_source;  // "rig.json guess" or "hand-eye", "+ stereo-LiDAR alignment"
  HandEyeResult hand_eye;
  // Ran when the hand-eye could not recover the rotation and rig.json has no guess.
  std::optional<TravelStructureExtrinsic> travel_structure;
  // Ran when stereo depth was given and PoseInitializerOptions::align_stereo_with_lidar.
  std::optional<StereoLidarAlignment> stereo_alignment;
  std::vector<PoseGraphEdge> edges;
  int num_image_edges = 0;
  int num_lidar_edges = 0;
  // LiDAR edges left out because an image edge of the same pair contradicts them: "target source:
  // LiDAR x deg, images y deg".
  std::vector<std::string> contradicted_lidar_edges;
  // Degenerate LiDAR edges left out (PoseInitializerOptions::use_degenerate_lidar_edges).
  std::vector<LidarPairRecord> degenerate_lidar_edges;
  // Edges of A_c v A_l left out by the cycle check after the hand-eye: "target source (LiDAR|images):
  // why".
  std::vector<std::string> inconsistent_edges;
  // Edges the solved pose graph does not reproduce within those tolerances (a longer loop that does
  // not close): "target source (LiDAR|images): x deg, y m ...". Not empty: the model may be wrong.
  std::vector<std::string> disagreeing_edges;
};

// "target source: degenerate (weakest direction ty)", for the console and initialization.json.
std::string DescribeDegenerateEdge(const LidarPairRecord& pair);

// `registration_path`: lidar_registrator's output folder (pairs.txt); may be empty (no LiDAR edges).
// `depth_path`: stereo_depth's output folder, for the stereo-LiDAR alignment; may be empty.
PoseInitialization InitializePoses(const std::string& database_path,
                                   const StationDataset& dataset,
                                   const std::string& registration_path,
                                   const PoseInitializerOptions& options,
                                   const std::string& depth_path = "");

// The existing-COLMAP-workflow variant: `models` (colmap mapper's, of the same database; ReadModels in
// bridge/initialization/model_completion.h, the largest first) are rescaled to metres in place
// (`existing->scales` returns the factors) and cam_from_lidar chosen:
// - stereo rig: each model's scale is the median ratio of depth prior to model depth over its landmark
//   observations; cam_from_lidar the guess or hand-eye with the models' relative poses as image motions;
// - monocular rig: the first model's similarity hand-eye gives both (or the guess, with the scale fitted
//   to the LiDAR motions through it); planar motion names its unobservable axis in `hand_eye`; the
//   other models are scaled to the LiDAR motions.
// Then the stations the models did not register, and the other models, are placed through the LiDAR
// pose graph (CompleteThroughLidar) in the first model's frame; stations no edge reaches are listed
// with the kind of edge missing. `cameras` holds the models' cameras. With `depth_path` (stereo_depth's
// output) cam_from_lidar is then refined by the stereo-LiDAR alignment, as in InitializePoses.
struct ExistingModels {
  std::vector<colmap::Reconstruction> models;  // rescaled to metres in place
  std::vector<double> scales;                  // the factors, one per model
};
PoseInitialization InitializeFromModels(const std::string& database_path,
                                        const StationDataset& dataset,
                                        const std::string& registration_path,
                                        const PoseInitializerOptions& options,
                                        ExistingModels* existing,
                                        const std::string& depth_path = "");

// The monocular initialisation: cam_from_lidar from rig.json's guess (if allowed and present), else
// from the similarity hand-eye (one scale per motion) between COLMAP's two-view geometry of the
// verified image pairs (EstimateImagePairDirections: rotation and translation direction) and the
// LiDAR motions of the same station pairs; then every station of the largest LiDAR component is placed through its
// LiDAR pose, cam_from_world = cam_from_lidar * inverse(world_from_lidar): the LiDAR trajectory is
// metric and, on forward motion, more reliable than a monocular model. Stations outside that
// component are listed as unreachable.
PoseInitialization InitializeMonocular(const std::string& database_path,
                                       const StationDataset& dataset,
                                       const std::string& registration_path,
                                       const PoseInitializerOptions& options);

// Writes a COLMAP sparse model with the initial poses and landmarks triangulated by COLMAP's own
// triangulator at those poses (TriangulateAtPoses); the cameras are the database's, or
// `initialization.cameras` where given.
void TriangulateInitialModel(const std::string& database_path,
                             const PoseInitialization& initialization,
                             const std::string& output_path);

}  // namespace colmap_lidar
