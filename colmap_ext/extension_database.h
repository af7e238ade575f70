// colmap-lidar's own tables inside a COLMAP 3.10 database file.
//
// COLMAP keeps its SQLite handle private, so this class opens a second connection to the same file. The
// tables reference COLMAP's `images` / `cameras` rows with ON DELETE CASCADE; COLMAP enables foreign keys on
// its own connection, so `colmap database_cleaner` and friends keep our rows consistent with theirs.
//
//   depth_priors(image_id, point2D_idx, depth, sigma)   one row per keypoint with a stereo depth [m]
//   lidar_frames(frame_id, image_id, path, cam_from_lidar_guess_{qw,qx,qy,qz,tx,ty,tz} nullable)
//   rig(rig_id, left_camera_id, right camera model/size/params, right_from_left_{qw..tz})
//
// Conventions: transforms are target_from_source (x_target = R x_source + t). Quaternions are stored w first
// (qw qx qy qz) in the database; in memory they are Eigen quaternions (xyzw storage), as in COLMAP.
// Every write is one transaction (BEGIN IMMEDIATE ... COMMIT): a failed write leaves the tables unchanged.
#pragma once

#include "colmap_ext/sqlite_connection.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"
#include "colmap/util/types.h"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace colmap_lidar {

// The z-depth of one keypoint measured by stereo, with its standard deviation sigma_d = d^2/(b f) sigma_p.
struct DepthPrior {
  colmap::point2D_t point2D_idx = colmap::kInvalidPoint2DIdx;
  double depth = 0;  // metres along the camera's z axis
  double sigma = 0;  // metres
};

// One station's accumulated LiDAR cloud, attached to the station's left image.
struct LidarFrame {
  int64_t frame_id = -1;  // assigned by the database
  colmap::image_t image_id = colmap::kInvalidImageId;
  std::string path;  // relative to the dataset root, e.g. "lidar/000.pcd"
  std::optional<colmap::Rigid3d> cam_from_lidar_guess;
};

// The stereo rig of a station: the left camera is COLMAP's camera `left_camera_id`; the right camera only
// lives here because COLMAP never sees right images.
struct StereoRig {
  colmap::camera_t left_camera_id = colmap::kInvalidCameraId;
  colmap::Camera right_camera;
  colmap::Rigid3d right_from_left;

  double BaselineMeters() const { return right_from_left.translation.norm(); }
};

class ExtensionDatabase {
 public:
  using Mode = SqliteConnection::Mode;

  // Opens an existing COLMAP database (throws std::runtime_error naming the file if it is missing, is not
  // a COLMAP database, or is locked). In kReadWrite mode our tables are created if absent.
  explicit ExtensionDatabase(const std::string& path,
                             Mode mode = Mode::kReadWrite,
                             int busy_timeout_ms = 5000);

  const std::string& Path() const { return connection_.Path(); }

  // Depth priors. Write replaces all rows of the given image in one transaction.
  void WriteDepthPriors(colmap::image_t image_id, const std::vector<DepthPrior>& priors);
  // Several images in one transaction (all or nothing).
  void WriteDepthPriors(const std::map<colmap::image_t, std::vector<DepthPrior>>& priors_per_image);
  std::vector<DepthPrior> ReadDepthPriors(colmap::image_t image_id) const;
  size_t NumDepthPriors() const;
  void ClearDepthPriors();

  // LiDAR frames. Write inserts or replaces the frame of frame.image_id; returns its frame_id.
  int64_t WriteLidarFrame(const LidarFrame& frame);
  std::vector<LidarFrame> ReadLidarFrames() const;
  std::optional<LidarFrame> ReadLidarFrameOfImage(colmap::image_t image_id) const;

  // The station rig (one per database).
  void WriteRig(const StereoRig& rig);
  std::optional<StereoRig> ReadRig() const;

 private:
  void CreateTables();
  bool HasOurTables() const;

  SqliteConnection connection_;
};

}  // namespace colmap_lidar
