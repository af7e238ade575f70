// COLMAP's dense workspace layout, written from our own depth and normal maps so that COLMAP's tools
// (`colmap stereo_fusion --input_type geometric`, `poisson_mesher`, `delaunay_mesher`) run on it:
//
//   ROOT/images/<image name>                          the image (8-bit colour)
//   ROOT/sparse/{cameras,images,points3D}.bin          the model, PINHOLE cameras (see below)
//   ROOT/stereo/depth_maps/<image name>.geometric.bin z-depth [m], COLMAP's DepthMap format, 0 = none
//   ROOT/stereo/normal_maps/<image name>.geometric.bin unit normals in the camera frame, facing it
//   ROOT/stereo/fusion.cfg, ROOT/stereo/patch-match.cfg
//
// Pixel convention: our maps follow COLMAP's sparse convention (pixel (row, col) is centred at image
// coordinates (col + 0.5, row + 0.5)), but COLMAP's MVS code back-projects pixel (row, col) at (col, row).
// The workspace's cameras therefore carry the principal point shifted by -0.5 px, which makes COLMAP's
// fusion place our depths exactly where we measured them.
#pragma once

#include "colmap/scene/reconstruction.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace colmap_lidar {

class DenseWorkspace {
 public:
  explicit DenseWorkspace(std::string root);  // creates the folders

  const std::string& Root() const { return root_; }
  std::string ImagePath(const std::string& image_name) const;
  std::string DepthMapPath(const std::string& image_name) const;
  std::string NormalMapPath(const std::string& image_name) const;

  // The model with its cameras converted to the workspace's PINHOLE cameras. Throws
  // std::invalid_argument naming a camera whose model has distortion (undistort first:
  // colmap::UndistortReconstruction and camera_undistortion.h, as the densifier does).
  void WriteSparse(const colmap::Reconstruction& reconstruction) const;
  // fusion.cfg lists the images; patch-match.cfg gives each "__auto__, num_source_images".
  void WriteConfigs(const std::vector<std::string>& image_names, int num_source_images = 20) const;

  void CopyImage(const std::string& image_name, const std::string& source_path) const;
  void WriteImage(const std::string& image_name, const cv::Mat& image) const;
  // depth: CV_32F, metres, 0 = none. normals: CV_32FC3 (x, y, z), zero = none.
  void WriteDepthMap(const std::string& image_name, const cv::Mat& depth) const;
  void WriteNormalMap(const std::string& image_name, const cv::Mat& normals) const;
  cv::Mat ReadDepthMap(const std::string& image_name) const;
  cv::Mat ReadNormalMap(const std::string& image_name) const;

 private:
  std::string root_;
};

// The images that ROOT/stereo/fusion.cfg lists (WriteConfigs). Reads only: call it before
// constructing a DenseWorkspace on a folder that may not be one. Throws std::runtime_error naming
// the file when it cannot be read.
std::vector<std::string> ReadFusionImageNames(const std::string& root);

// True for camera models without distortion (SIMPLE_PINHOLE, PINHOLE).
bool IsPinholeCamera(const colmap::Camera& camera);

// Reads one of COLMAP's depth maps (e.g. our stereo output) into a CV_32F matrix.
cv::Mat ReadColmapDepthMap(const std::string& path);

}  // namespace colmap_lidar
