// The colmap-lidar commands implemented in bridge/. Each is `int RunX(int argc, char** argv)` in COLMAP's
// style: argv[0] is the command name, options are parsed with CommandOptions (so `--project_path
// file.ini` works as in COLMAP), and the return value is the process exit code. Errors are thrown as
// exceptions; the dispatcher turns them into one "ERROR: ..." line and a non-zero exit. Each command parses
// its options and calls its step's typed function (steps.h), which `pipeline` calls as well.
#pragma once

namespace colmap_lidar {

// Creates a COLMAP database (or opens an existing one) and adds colmap-lidar's tables.
int RunDatabaseCreator(int argc, char** argv);

// Prints what a database holds: COLMAP's images/keypoints/matches and our depth priors, LiDAR frames, rig.
int RunDatabaseInfo(int argc, char** argv);

// Imports a station dataset into a COLMAP database: camera from rig.json, COLMAP SIFT extraction and
// exhaustive matching, our rig and lidar_frames rows (colmap_ext/dataset_import.h).
int RunImportDataset(int argc, char** argv);

// Converts a KITTI raw drive (images, Velodyne sweeps, calibration) into a station dataset
// (colmap_ext/kitti_import.h).
int RunImportKitti(int argc, char** argv);

// SGM stereo depth per station in the original left image grid (colmap_ext/stereo_depth.h).
int RunStereoDepth(int argc, char** argv);

// Depth priors of the database's keypoints from the stereo depth maps (colmap_ext/depth_prior_extractor.h).
int RunDepthPriorExtractor(int argc, char** argv);

// Registers all station clouds (BSC + RANSAC + ICP), builds the LiDAR pose graph A_l and writes
// pairs.txt, lidar_poses.txt and summary.txt.
int RunLidarRegistrator(int argc, char** argv);
int RunDeskewSweeps(int argc, char** argv);
// The frames of a drive that go on to the camera steps, as a registration folder of their own.
int RunSelectFrames(int argc, char** argv);

// The joint problem (reprojection + depth priors + LiDAR point-to-plane + cam_from_lidar) inside COLMAP's
// bundle adjuster on a sparse model; writes the refined model, cam_from_lidar.txt, report.json, plots.
int RunJointAdjuster(int argc, char** argv);

// Initial poses (image and LiDAR edges, hand-eye cam_from_lidar, spanning tree + pose graph) and
// landmarks by COLMAP's triangulator: a metric COLMAP model for the joint adjuster.
int RunPoseInitializer(int argc, char** argv);

// The dense model: stereo depth refined by LiDAR (remove, fill), fused.ply, lidar_map.ply and COLMAP's
// dense workspace (bridge/dense/densifier.h).
int RunDensifier(int argc, char** argv);

// Every step from a station dataset to the refined model, restartable
// (RunFullPipeline, bridge/pipeline/pipeline_controller.h).
int RunPipeline(int argc, char** argv);

// Accuracy of a cloud against ground_truth/surface.ply: distances, completeness, density, plots.
int RunEvaluateModel(int argc, char** argv);

// Error of an estimated cam_from_lidar and of a sparse model's station poses against ground truth.
int RunEvaluateCalibration(int argc, char** argv);

// A trajectory (lidar_poses.txt, a COLMAP model, KITTI or TUM poses) against a reference: KITTI's
// relative errors, per-step and absolute errors, plots (bridge/evaluation/trajectory_evaluation.h).
int RunEvaluateTrajectory(int argc, char** argv);

// The database's depth priors against ground_truth/depth/: errors in units of sigma_d, at and away
// from depth edges (colmap_ext/depth_prior_evaluation.h).
int RunEvaluateDepthPriors(int argc, char** argv);

// A dense workspace's depth maps against ground_truth/depth/: coverage and error
// (colmap_ext/dense_depth_evaluation.h).
int RunEvaluateDenseDepth(int argc, char** argv);

// cam_from_lidar from image edges and LiDAR depth discontinuities (Levinson & Thrun 2013), the
// baseline of the paper's comparison (bridge/baselines/edge_calibration.h).
int RunCalibrateEdges(int argc, char** argv);

}  // namespace colmap_lidar
