#include "bridge/evaluation/calibration_evaluation.h"

#include <gtest/gtest.h>

#include <random>

namespace colmap_lidar {
namespace {

colmap::Rigid3d RandomPose(std::mt19937* rng) {
  std::normal_distribution<double> n;
  const Eigen::Vector3d axis = Eigen::Vector3d(n(*rng), n(*rng), n(*rng)).normalized();
  return colmap::Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(n(*rng), axis)),
                         Eigen::Vector3d(n(*rng), n(*rng), n(*rng)));
}

// A model whose stations are the truth seen from another (rigid or similarity) world frame.
colmap::Reconstruction ModelOfTruth(const std::map<std::string, colmap::Rigid3d>& truth,
                                    const colmap::Rigid3d& model_from_true_world,
                                    double scale) {
  colmap::Reconstruction reconstruction;
  colmap::Camera camera = colmap::Camera::CreateFromModelName(1, "PINHOLE", 800, 1028, 752);
  reconstruction.AddCamera(camera);
  colmap::image_t image_id = 1;
  for (const auto& [name, cam_from_world] : truth) {
    colmap::Image image;
    image.SetImageId(image_id);
    image.SetCameraId(1);
    image.SetName("left/" + name + ".png");
    colmap::Rigid3d cam_from_model = cam_from_world * colmap::Inverse(model_from_true_world);
    cam_from_model.translation *= scale;
    image.CamFromWorld() = cam_from_model;
    reconstruction.AddImage(image);
    reconstruction.RegisterImage(image_id++);
  }
  return reconstruction;
}

class CalibrationEvaluationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937 rng(5);
    for (const char* name : {"000", "001", "002", "003", "004", "005"})
      truth_[name] = RandomPose(&rng);
    cam_from_lidar_ = RandomPose(&rng);
    gauge_ = RandomPose(&rng);
  }
  std::map<std::string, colmap::Rigid3d> truth_;
  colmap::Rigid3d cam_from_lidar_, gauge_;
};

TEST_F(CalibrationEvaluationTest, TruthGivesZeroWhateverTheModelGauge) {
  const CalibrationEvaluation result = EvaluateCalibration(cam_from_lidar_,
                                                           cam_from_lidar_,
                                                           truth_,
                                                           ModelOfTruth(truth_, gauge_, 1.0),
                                                           TrajectoryAlignment::kRigid);
  EXPECT_EQ(result.num_stations_evaluated, 6u);
  EXPECT_NEAR(result.cam_from_lidar_rotation_error_deg, 0, 1e-9);
  EXPECT_NEAR(result.cam_from_lidar_translation_error_mm, 0, 1e-9);
  EXPECT_LT(result.max_position_error_mm, 1e-6);
  EXPECT_LT(result.max_rotation_error_deg, 1e-6);
  EXPECT_EQ(result.alignment, TrajectoryAlignment::kRigid);
}

// Stations along a straight line whose estimated centres carry 1 mm of noise and whose
// orientations are right: the centres alone would leave the alignment's rotation about the line to
// that noise.
TEST_F(CalibrationEvaluationTest, AStraightDriveIsAlignedByTheCamerasAxesToo) {
  std::map<std::string, colmap::Rigid3d> straight;
  const Eigen::Quaterniond forward(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
  for (int i = 0; i < 7; ++i) {
    straight["00" + std::to_string(i)] =
        colmap::Rigid3d(forward, -(forward * Eigen::Vector3d(2.0 * i, 0, 0)));
  }
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.001);
  colmap::Reconstruction model = ModelOfTruth(straight, gauge_, 1.0);
  for (const colmap::image_t id : model.RegImageIds()) {
    model.Image(id).CamFromWorld().translation +=
        Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  }
  const CalibrationEvaluation result = EvaluateCalibration(
      cam_from_lidar_, cam_from_lidar_, straight, model, TrajectoryAlignment::kRigid);
  // Measured 0.0076 deg: the centres' noise over the axes' 4 m lever.
  EXPECT_LT(result.max_rotation_error_deg, 0.025);
  EXPECT_LT(result.max_position_error_mm, 5);
}

TEST_F(CalibrationEvaluationTest, KnownErrorsAreMeasured) {
  // An extrinsic 3 deg and 50 mm off, as the simulator's default guess.
  colmap::Rigid3d guess = cam_from_lidar_;
  guess.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(3 * M_PI / 180, Eigen::Vector3d(1, 1, 0).normalized())) *
      guess.rotation;
  guess.translation += Eigen::Vector3d(0.03, 0, 0.04);
  colmap::Reconstruction model = ModelOfTruth(truth_, gauge_, 1.0);
  const CalibrationEvaluation result =
      EvaluateCalibration(cam_from_lidar_, guess, truth_, model, TrajectoryAlignment::kRigid);
  EXPECT_NEAR(result.cam_from_lidar_rotation_error_deg, 3.0, 1e-9);
  EXPECT_NEAR(result.cam_from_lidar_translation_error_mm, 50.0, 1e-9);
  EXPECT_NEAR(result.cam_from_lidar_translation_error_in_cam_mm.z(), 40.0, 1e-9);
}

TEST_F(CalibrationEvaluationTest, ScaledModelNeedsSimilarityAlignment) {
  const colmap::Reconstruction model = ModelOfTruth(truth_, gauge_, 0.5);
  const CalibrationEvaluation rigid = EvaluateCalibration(
      cam_from_lidar_, cam_from_lidar_, truth_, model, TrajectoryAlignment::kRigid);
  EXPECT_GT(rigid.mean_position_error_mm,
            100);  // the rigid alignment exposes the scale error
  const CalibrationEvaluation similarity = EvaluateCalibration(
      cam_from_lidar_, cam_from_lidar_, truth_, model, TrajectoryAlignment::kSimilarity);
  EXPECT_NEAR(similarity.alignment_scale, 2.0, 1e-9);
  EXPECT_LT(similarity.max_position_error_mm, 1e-6);
}

TEST_F(CalibrationEvaluationTest, MissingStationsAreReportedAndTooFewRejected) {
  auto partial = truth_;
  partial.erase("003");
  colmap::Reconstruction model = ModelOfTruth(partial, gauge_, 1.0);
  const CalibrationEvaluation result = EvaluateCalibration(
      cam_from_lidar_, cam_from_lidar_, truth_, model, TrajectoryAlignment::kRigid);
  EXPECT_EQ(result.missing_stations, std::vector<std::string>{"003"});
  EXPECT_EQ(result.num_stations_evaluated, 5u);
  const std::map<std::string, colmap::Rigid3d> two = {*truth_.begin(), *truth_.rbegin()};
  EXPECT_THROW(EvaluateCalibration(cam_from_lidar_,
                                   cam_from_lidar_,
                                   truth_,
                                   ModelOfTruth(two, gauge_, 1.0),
                                   TrajectoryAlignment::kRigid),
               std::invalid_argument);
}

}  // namespace
}  // namespace colmap_lidar
