#include "colmap_ext/kitti_calibration.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

class KittiCalibrationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("kitti_calib_" + std::to_string(std::random_device()()));
    // KITTI-like values: P_rect_0X = K [I | t_X] with the small tz of cameras 2 and 3.
    Eigen::Matrix3d k;
    k << 721.5377, 0, 609.5593, 0, 721.5377, 172.854, 0, 0, 1;
    const std::vector<Eigen::Vector3d> offsets = {
        {0, 0, 0}, {-0.5372, 0, 0}, {0.0598, -0.0004, 0.0027}, {-0.4732, 0.0020, 0.0027}};
    for (const Eigen::Vector3d& t : offsets) {
      Eigen::Matrix<double, 3, 4> p;
      p << k, k * t;
      files_.p_rect.push_back(p);
    }
    files_.r_rect_00 =
        Eigen::AngleAxisd(0.012, Eigen::Vector3d(0.3, -0.8, 0.5).normalized()).toRotationMatrix();
    Eigen::Matrix3d r;
    r << 7.533745e-03, -9.999714e-01, -6.166020e-04, 1.480249e-02, 7.280733e-04, -9.998902e-01,
        9.998621e-01, 7.523790e-03, 1.480755e-02;
    files_.cam0_from_velo =
        colmap::Rigid3d(Eigen::Quaterniond(r).normalized(),
                        Eigen::Vector3d(-4.069766e-03, -7.631618e-02, -0.2717806));
    files_.width = 1242;
    files_.height = 375;
    WriteKittiCalibration(dir_.string(), files_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  KittiCalibrationFiles files_;
};

// KITTI's own projection y = P_rect_0X R_rect_00 [R|T] x and ours (the PINHOLE camera after
// cam_from_velo) agree on points in front of the camera.
TEST_F(KittiCalibrationTest, ImportedCameraProjectsAsKittisFormula) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> lateral(-10, 10), ahead(4, 60);
  for (int index = 0; index < 4; ++index) {
    const KittiCamera camera = ReadKittiCamera(dir_.string(), index);
    EXPECT_EQ(camera.camera.ModelName(), "PINHOLE");
    EXPECT_EQ(camera.camera.width, 1242u);
    EXPECT_EQ(camera.camera.height, 375u);
    const Eigen::Matrix3d r = files_.cam0_from_velo.rotation.toRotationMatrix();
    double worst_px = 0;
    for (int k = 0; k < 200; ++k) {
      // Points ahead of the car: x forward in the Velodyne frame.
      const Eigen::Vector3d point_in_velo(ahead(rng), lateral(rng), 0.2 * lateral(rng));
      const Eigen::Vector3d kitti =
          files_.p_rect[index] *
          (files_.r_rect_00 * (r * point_in_velo + files_.cam0_from_velo.translation))
              .homogeneous();
      const Eigen::Vector2d ours =
          camera.camera.ImgFromCam((camera.cam_from_velo * point_in_velo).hnormalized());
      worst_px = std::max(worst_px, (kitti.hnormalized() - ours).norm());
    }
    EXPECT_LT(worst_px, 1e-9) << "camera " << index;
  }
  const colmap::Rigid3d right_from_left =
      KittiRightFromLeft(ReadKittiCamera(dir_.string(), 2), ReadKittiCamera(dir_.string(), 3));
  EXPECT_NEAR(right_from_left.translation.x(), -0.4732 - 0.0598, 1e-12);
  EXPECT_NEAR(right_from_left.rotation.angularDistance(Eigen::Quaterniond::Identity()), 0, 1e-15);
}

TEST_F(KittiCalibrationTest, BadFilesNameTheFileAndTheKey) {
  const std::string cam_path = (dir_ / "calib_cam_to_cam.txt").string();
  std::ifstream in(cam_path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto expect_error = [&](const std::string& contents, int index, const std::string& words) {
    std::ofstream(cam_path) << contents;
    try {
      ReadKittiCamera(dir_.string(), index);
      ADD_FAILURE() << "no error for " << words;
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
    }
  };
  std::string without_p2 = text;
  without_p2.erase(
      without_p2.find("P_rect_02"),
      without_p2.find('\n', without_p2.find("P_rect_02")) - without_p2.find("P_rect_02") + 1);
  expect_error(without_p2, 2, "calib_cam_to_cam.txt: no P_rect_02");
  std::string short_p = text;
  const size_t p0 = short_p.find("P_rect_00");
  short_p.erase(short_p.find('\n', p0) - 22, 22);  // the last value
  expect_error(short_p, 0, "P_rect_00 has 11 values, not 12");
  expect_error(text + "this line has no colon\n", 0, "calib_cam_to_cam.txt:");
  std::string nan_value = text;
  nan_value.replace(nan_value.find(' ', nan_value.find("R_rect_00:") + 11), 1, " nan ");
  expect_error(nan_value, 0, "R_rect_00 has a value that is not a finite number");
  fs::remove(dir_ / "calib_velo_to_cam.txt");
  expect_error(text, 0, "calib_velo_to_cam.txt");
}

}  // namespace
}  // namespace colmap_lidar
