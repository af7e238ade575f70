#include "colmap_ext/dense_workspace.h"

#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/reconstruction.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace colmap_lidar {
namespace {

colmap::Reconstruction OneImageModel(const std::string& camera_model) {
  colmap::Reconstruction reconstruction;
  colmap::Camera camera = colmap::Camera::CreateFromModelName(1, camera_model, 500, 64, 48);
  reconstruction.AddCamera(camera);
  colmap::Image image;
  image.SetImageId(1);
  image.SetCameraId(1);
  image.SetName("left/000.png");
  image.SetPoints2D(std::vector<Eigen::Vector2d>(1, Eigen::Vector2d(10, 10)));
  reconstruction.AddImage(image);
  reconstruction.RegisterImage(1);
  return reconstruction;
}

TEST(DenseWorkspace, MapsRoundTripInColmapsFormat) {
  testing::ScopedTempDir dir;
  const DenseWorkspace workspace(dir.File("dense"));
  cv::Mat depth(48, 64, CV_32F, cv::Scalar(0));
  cv::Mat normals(48, 64, CV_32FC3, cv::Scalar(0, 0, 0));
  depth.at<float>(3, 5) = 2.5f;
  depth.at<float>(47, 63) = 7.25f;
  normals.at<cv::Vec3f>(3, 5) = cv::Vec3f(0.6f, 0, -0.8f);
  workspace.WriteDepthMap("left/000.png", depth);
  workspace.WriteNormalMap("left/000.png", normals);
  EXPECT_TRUE(std::filesystem::is_regular_file(
      dir.File("dense/stereo/depth_maps/left/000.png.geometric.bin")));
  const cv::Mat depth_back = workspace.ReadDepthMap("left/000.png");
  const cv::Mat normals_back = workspace.ReadNormalMap("left/000.png");
  EXPECT_EQ(cv::norm(depth_back, depth, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(normals_back, normals, cv::NORM_INF), 0);
  EXPECT_THROW(workspace.ReadDepthMap("left/001.png"), std::runtime_error);
}

TEST(DenseWorkspace, SparseModelCarriesPinholeCamerasShiftedHalfAPixel) {
  testing::ScopedTempDir dir;
  const DenseWorkspace workspace(dir.File("dense"));
  workspace.WriteSparse(OneImageModel("SIMPLE_PINHOLE"));
  workspace.WriteConfigs({"left/000.png"});
  colmap::Reconstruction back;
  back.Read(dir.File("dense/sparse"));
  const colmap::Camera& camera = back.Camera(1);
  EXPECT_EQ(camera.ModelName(), "PINHOLE");
  EXPECT_DOUBLE_EQ(camera.FocalLengthX(), 500);
  EXPECT_DOUBLE_EQ(camera.FocalLengthY(), 500);
  EXPECT_DOUBLE_EQ(camera.PrincipalPointX(), 32 - 0.5);
  EXPECT_DOUBLE_EQ(camera.PrincipalPointY(), 24 - 0.5);
  std::ifstream patch_match(dir.File("dense/stereo/patch-match.cfg"));
  std::string line1, line2;
  std::getline(patch_match, line1);
  std::getline(patch_match, line2);
  EXPECT_EQ(line1, "left/000.png");
  EXPECT_EQ(line2, "__auto__, 20");

  // A camera with distortion is refused, naming it.
  try {
    workspace.WriteSparse(OneImageModel("OPENCV"));
    ADD_FAILURE() << "a distorted camera was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("OPENCV"), std::string::npos);
  }
}

}  // namespace
}  // namespace colmap_lidar
