// The station dataset format (docs/dataset_format.md):
//
//   DATASET/rig.json
//   DATASET/images/left/<station>.png, DATASET/images/right/<station>.png (stereo rigs only)
//   DATASET/lidar/<station>.pcd (or .ply, KITTI .bin)       cloud in the station's LiDAR frame
//   DATASET/ground_truth/{cam_from_world.txt, cam_from_lidar.txt, surface.ply, depth/<station>.bin}
//
// Conventions: every transform is target_from_source (x_target = R x_source + t), translations in metres.
// Quaternions are written w first (qw qx qy qz) in rig.json and the .txt files; in memory they are Eigen
// quaternions (xyzw storage) inside colmap::Rigid3d.
#pragma once

#include "lidar/util/atomic_file.h"  // WriteFileAtomically, used with the pose files

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace colmap_lidar {

struct StationRig {
  colmap::Camera left;
  // Absent for a monocular rig (no "right" in rig.json, no images/right/): depth and scale then come
  // from the LiDAR alone.
  std::optional<colmap::Camera> right;
  // Meaningful only with `right`.
  colmap::Rigid3d right_from_left;
  std::optional<colmap::Rigid3d> cam_from_lidar_guess;
  // "cam_from_lidar_guess": {..., "sigma_rotation_deg": r, "sigma_translation_m": t}: how well the
  // guess is known (one standard deviation per camera axis); the joint adjuster then takes the guess
  // as a Gaussian prior. Absent: the guess is only a start.
  struct GuessSigma {
    double rotation_deg = 0;
    double translation_m = 0;
  };
  std::optional<GuessSigma> cam_from_lidar_guess_sigma;
  std::string lidar_model;  // e.g. "VLP-16"; empty if not given
  // The LiDAR's range noise (1 sigma) [m]; 0 if not given. The one home of this quantity: the joint
  // adjuster's nominal E_l sigma and the stereo-LiDAR alignments take LidarRangeNoiseM().
  double lidar_range_noise_m = 0;
  // A spinning LiDAR's typical range noise, used when rig.json gives none.
  static constexpr double kDefaultLidarRangeNoiseM = 0.02;
  double LidarRangeNoiseM() const {
    return lidar_range_noise_m > 0 ? lidar_range_noise_m : kDefaultLidarRangeNoiseM;
  }
  // "lidar": {"sweep": {"start_azimuth_deg": a, "counter_clockwise": b}}: each cloud is one revolution
  // of a rotating LiDAR on a moving platform (import_kitti writes it), which the pipeline de-skews.
  struct LidarSweep {
    double start_azimuth_deg = 180.0;  // behind the platform (KITTI's HDL-64)
    bool counter_clockwise = true;
  };
  std::optional<LidarSweep> lidar_sweep;
  // "lidar": {"moving_platform": true}: the stations are frames of a moving platform (a car, a
  // backpack) even where the clouds need no de-skewing (motion-compensated scans); implied by `sweep`.
  bool moving_platform = false;

  bool IsMovingPlatform() const { return moving_platform || lidar_sweep.has_value(); }

  bool IsStereo() const { return right.has_value(); }
  // 0 for a monocular rig.
  double BaselineMeters() const { return IsStereo() ? right_from_left.translation.norm() : 0.0; }
  // b f [m px], disparity times depth (0 without a right camera); f is the left camera's first
  // parameter, the rectified focal length.
  double BaselineFocal() const { return BaselineMeters() * left.params[0]; }
};

// Throws std::runtime_error naming the file and the offending key (missing key, unknown camera model,
// wrong number of parameters, non-finite values, zero baseline, ...).
StationRig ReadRigJson(const std::string& path);
void WriteRigJson(const std::string& path, const StationRig& rig);

struct StationDataset {
  std::string root;
  StationRig rig;
  std::vector<std::string> stations;     // sorted file stems, e.g. "000"
  std::vector<std::string> cloud_paths;  // absolute, one per station
  // DATASET/timestamps.txt: each station's frame time [s] (empty when the file is absent).
  std::vector<double> frame_times;
  // DATASET/sweep_times.txt: each station's sweep start and end [s] (empty when absent).
  std::vector<std::pair<double, double>> sweep_times;

  std::string LeftImagePath(size_t i) const;
  std::string RightImagePath(size_t i) const;
  // "left/<station>.png" etc.: the image name as stored in COLMAP's database.
  std::string LeftImageName(size_t i) const;
  std::string GroundTruthPath(const std::string& name) const;
  // ground_truth/cam_from_world.txt (true poses; the simulator writes them).
  bool HasGroundTruth() const;
  // ground_truth/cam_from_lidar.txt (a reference extrinsic; import_kitti writes only this).
  bool HasReferenceExtrinsic() const;
};

// Reads and validates a dataset: rig.json, every left image has a cloud and, for a stereo rig, a right
// image; a monocular rig must not come with images/right/ (which would say rig.json lost its right
// camera). Throws
// std::runtime_error naming the missing or bad file.
StationDataset ReadStationDataset(const std::string& root);

// `dataset` with only the stations named in `kept` (in the dataset's order; the per-station lists
// follow). Throws std::runtime_error naming a station that the dataset does not have.
StationDataset RestrictToStations(StationDataset dataset, const std::vector<std::string>& kept);

// "<station> t" per line (timestamps.txt), stations in the order given.
void WriteStationTimes(const std::string& path,
                       const std::vector<std::string>& stations,
                       const std::vector<double>& times);
// "<station> start end" per line (sweep_times.txt).
void WriteSweepTimes(const std::string& path,
                     const std::vector<std::string>& stations,
                     const std::vector<std::pair<double, double>>& times);

// "<station> qw qx qy qz tx ty tz" per line (cam_from_world.txt, lidar_poses.txt, ...). '#' starts a comment.
std::map<std::string, colmap::Rigid3d> ReadNamedPoses(const std::string& path);
void WriteNamedPoses(const std::string& path,
                     const std::string& header_comment,
                     const std::map<std::string, colmap::Rigid3d>& poses);

// A single "qw qx qy qz tx ty tz" line (cam_from_lidar.txt).
colmap::Rigid3d ReadPoseFile(const std::string& path);
void WritePoseFile(const std::string& path,
                   const std::string& header_comment,
                   const colmap::Rigid3d& target_from_source);

}  // namespace colmap_lidar
