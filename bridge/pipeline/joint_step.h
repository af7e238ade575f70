// The joint adjuster as a pipeline step, a library call: reads a COLMAP sparse model and the data of
// the joint problem (depth priors, clouds, the pose graph), decides from the rig and the stations'
// motion what the problem holds (E_m and its weight, the vertical alignment, the LiDAR clock
// offset), runs bridge/joint/joint_adjuster.h and writes OUTPUT/ atomically: the refined model,
// cam_from_lidar.txt, camera_poses.*, report.json and its plots (docs/joint_adjuster.md). The
// `joint_adjuster` command and `pipeline` call it; so can any program linking colmap_lidar::pipeline.
#pragma once

#include "bridge/joint/joint_adjuster.h"
#include "bridge/joint/joint_problem_data.h"
#include "bridge/pipeline/capture_profile.h"
#include "colmap_ext/station_dataset.h"

#include <optional>
#include <string>

namespace colmap_lidar {

// The options of the joint adjuster as a step: the adjuster's (its mode, the held axes) and the data
// loading's.
struct JointAdjusterStepOptions {
  JointAdjusterOptions adjuster;
  JointDataOptions data;
  // On a moving platform (rig.json), estimate the LiDAR clock's offset from the cameras in E_m
  // (JointAdjusterOptions::estimate_time_offset).
  bool estimate_time_offset = true;
  // rig.json's guess without a sigma gives the value of the directions the data leave undetermined
  // (JointProblemData::cam_from_lidar_guess); the pipeline passes its pose initialiser's use_guess.
  bool use_guess = true;
  // Also write the model as text (cameras.txt, images.txt, points3D.txt).
  bool write_text = false;
  // The capture profile the pose initialiser decided, given in memory by the pipeline that ran it;
  // empty: the one recorded beside the input model (INPUT/capture_profile.json), else decided from
  // the dataset and the model.
  std::optional<CaptureProfile> profile;

  bool Check() const;
};
struct JointAdjusterPaths {
  std::string database_path;
  std::string input_path;
  // qw qx qy qz tx ty tz; empty: INPUT/cam_from_lidar.txt, else rig.json's guess.
  std::string cam_from_lidar_path;
  std::string output_path;
};
void RunJointAdjusterStep(const StationDataset& dataset,
                          const JointAdjusterPaths& paths,
                          JointAdjusterStepOptions options);

}  // namespace colmap_lidar
