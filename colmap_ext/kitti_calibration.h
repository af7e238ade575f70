// KITTI raw's calibration files in their published text format (Geiger, Lenz, Stiller, Urtasun, "Vision
// meets Robotics: The KITTI Dataset", IJRR 2013, and the raw-data development kit):
//   calib_cam_to_cam.txt   "key: values" lines; per camera X: S_rect_0X (width height), P_rect_0X
//                          (3x4, row-major), and R_rect_00 (3x3, row-major) rectifying camera 0
//   calib_velo_to_cam.txt  R: (3x3, row-major) and T: (3), camera 0 (unrectified) from the Velodyne
// Other keys ("calib_time", K_0X, D_0X, ...) are read but not used. KITTI projects a Velodyne point x
// into rectified image X as y = P_rect_0X * R_rect_00 * [R|T] * x; so the rectified camera X, as a
// PINHOLE camera with fx fy cx cy from P_rect_0X, sees
//   camX_from_velo = [I | K^-1 P_rect_0X[:,3]] * R_rect_00 * [R|T]
// with K the left 3x3 block of P_rect_0X (exact: KITTI's P_rect_02[2,3] is a few mm, not 0).
#pragma once

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"

#include <map>
#include <string>
#include <vector>

namespace colmap_lidar {

// Every "key: v1 v2 ..." line of a KITTI calibration file, values as numbers where they all parse
// ("calib_time: 15-Mar-2012 11:37:52" is kept out). Throws std::runtime_error naming the file (and the
// line for a line without a colon, or a rectification/extrinsic key with a NaN or non-number value).
std::map<std::string, std::vector<double>> ReadKittiCalibFile(const std::string& path);

struct KittiCamera {
  colmap::Camera camera;          // PINHOLE, the rectified image's size (S_rect_0X)
  colmap::Rigid3d cam_from_velo;  // the rectified camera from the Velodyne
  Eigen::Vector3d projection_offset = Eigen::Vector3d::Zero();  // K^-1 P_rect_0X[:,3] [m]
};

// Camera `index` (0..3) of CALIB_DIR; throws naming the file and the missing or malformed key.
KittiCamera ReadKittiCamera(const std::string& calib_dir, int index);

// Camera `index` (0..3) of a KITTI odometry sequence's calib.txt ("P0:" .. "P3:" 3x4 rectified
// projections and "Tr:" 3x4, the rectified camera 0 from the Velodyne), for images of the given size:
//   camX_from_velo = [I | K^-1 P_X[:,3]] * Tr.
// Throws naming the file and the missing or malformed key (a calib.txt without Tr among them).
KittiCamera ReadKittiOdometryCamera(const std::string& calib_file,
                                    int index,
                                    int width,
                                    int height);

// calib_imu_to_velo.txt of CALIB_DIR (R: 3x3 row-major, T: 3): velo_from_imu.
colmap::Rigid3d ReadKittiVeloFromImu(const std::string& calib_dir);

// The rectified right camera from the rectified left one: identity rotation, translation the difference
// of their projection offsets (about -0.54 m in x between cameras 2 and 3).
colmap::Rigid3d KittiRightFromLeft(const KittiCamera& left, const KittiCamera& right);

// Writes calib_cam_to_cam.txt and calib_velo_to_cam.txt for cameras 0..cameras.size()-1, all of one
// size, rectified with R_rect_00, in the published format; the inverse of ReadKittiCamera (for the
// simulator's KITTI layout and tests). `cam0_from_velo` is the unrectified camera 0.
struct KittiCalibrationFiles {
  std::vector<Eigen::Matrix<double, 3, 4>> p_rect;  // P_rect_00, P_rect_01, ...
  Eigen::Matrix3d r_rect_00 = Eigen::Matrix3d::Identity();
  colmap::Rigid3d cam0_from_velo;
  int width = 0, height = 0;
};
void WriteKittiCalibration(const std::string& calib_dir, const KittiCalibrationFiles& files);

}  // namespace colmap_lidar
