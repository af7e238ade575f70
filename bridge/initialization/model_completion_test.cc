#include "bridge/initialization/model_completion.h"

#include "tests/testing/generic_poses.h"
#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace colmap_lidar {
namespace {

using testing::Pose;

// Six stations 000..005 on a curve; cam_from_lidar generic; LiDAR edges exact.
struct Scene {
  colmap::Rigid3d cam_from_lidar = Pose(2.0, {0.4, -0.5, 0.6}, {0.19, -0.25, -0.05});
  std::vector<colmap::Rigid3d> cam_from_world;
  std::map<std::string, colmap::image_t> image_of_station;
  std::map<colmap::image_t, std::string> names;

  Scene() {
    for (int k = 0; k < 6; ++k) {
      cam_from_world.push_back(Pose(0.3 * k, {0.1, -1.0, 0.2}, {0.5 * k, 0.1 * k * k, 2.0 - k}));
      const std::string station = "00" + std::to_string(k);
      image_of_station[station] = k + 1;
      names[k + 1] = "left/" + station + ".png";
    }
  }

  LidarPairRecord Edge(int i, int j) const {
    LidarPairRecord pair;
    pair.target = "00" + std::to_string(i);
    pair.source = "00" + std::to_string(j);
    pair.target_from_source = colmap::Inverse(cam_from_lidar) * cam_from_world[i] *
                              colmap::Inverse(cam_from_world[j]) * cam_from_lidar;
    pair.num_inliers = 500;
    return pair;
  }

  // A metric model of `stations` in a frame of its own: model_from_world applied to every pose.
  colmap::Reconstruction Model(const std::vector<int>& stations,
                               const colmap::Rigid3d& model_from_world) const {
    colmap::Reconstruction model;
    model.AddCamera(colmap::Camera::CreateFromModelName(1, "PINHOLE", 500, 640, 480));
    for (const int k : stations) {
      colmap::Image image;
      image.SetImageId(k + 1);
      image.SetName(names.at(k + 1));
      image.SetCameraId(1);
      image.CamFromWorld() = cam_from_world[k] * colmap::Inverse(model_from_world);
      model.AddImage(image);
      model.RegisterImage(k + 1);
    }
    return model;
  }
};

double PoseError(const colmap::Rigid3d& a, const colmap::Rigid3d& b) {
  return (a.translation - b.translation).norm() + a.rotation.angularDistance(b.rotation);
}

// Model 0 registers 000 and 001, model 1 (another frame) 003 and 004; LiDAR edges 001-002 and
// 002-003 join them; 005 has no edge. Everything reachable comes out exactly in model 0's frame.
TEST(ModelCompletion, StationsAndModelsArePlacedThroughTheLidarInTheFirstModelsFrame) {
  const Scene scene;
  const colmap::Rigid3d first_from_world = Pose(0.7, {1, 2, 3}, {4, -5, 6});
  const colmap::Reconstruction first = scene.Model({0, 1}, first_from_world);
  const colmap::Reconstruction second = scene.Model({3, 4}, Pose(-1.2, {3, -1, 0}, {-9, 1, 2}));
  const CompletedPoses completed = CompleteThroughLidar({&first, &second},
                                                        scene.image_of_station,
                                                        scene.names,
                                                        {scene.Edge(1, 2), scene.Edge(2, 3)},
                                                        scene.cam_from_lidar,
                                                        ModelCompletionOptions());
  ASSERT_EQ(completed.cam_from_world.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_LT(PoseError(completed.cam_from_world.at(k + 1),
                        scene.cam_from_world[k] * colmap::Inverse(first_from_world)),
              1e-6)
        << "station " << k;
  }
  EXPECT_EQ(completed.num_model_edges, 2);
  EXPECT_EQ(completed.num_lidar_edges, 2);
  ASSERT_EQ(completed.unreachable.size(), 1u);
  EXPECT_NE(completed.unreachable.at("left/005.png").find("accepted no edge"), std::string::npos);
}

// Without the edge 002-003 the second model is left out, and says why.
TEST(ModelCompletion, UnreachableStationsSayWhichEdgeIsMissing) {
  const Scene scene;
  const colmap::Reconstruction first = scene.Model({0, 1}, colmap::Rigid3d());
  const colmap::Reconstruction second = scene.Model({3, 4}, Pose(-1.2, {3, -1, 0}, {-9, 1, 2}));
  const CompletedPoses completed = CompleteThroughLidar({&first, &second},
                                                        scene.image_of_station,
                                                        scene.names,
                                                        {scene.Edge(1, 2), scene.Edge(4, 5)},
                                                        scene.cam_from_lidar,
                                                        ModelCompletionOptions());
  EXPECT_EQ(completed.cam_from_world.size(), 3u);
  ASSERT_EQ(completed.unreachable.size(), 3u);
  EXPECT_NE(completed.unreachable.at("left/003.png").find("registered in model 1"),
            std::string::npos);
  EXPECT_NE(completed.unreachable.at("left/005.png").find("do not reach"), std::string::npos);
}

TEST(ModelCompletion, ReadModelsTakesAFolderOrItsModelSubfoldersLargestFirst) {
  testing::ScopedTempDir dir;
  const Scene scene;
  std::filesystem::create_directories(dir.File("sparse/0"));
  std::filesystem::create_directories(dir.File("sparse/1"));
  scene.Model({0, 1}, colmap::Rigid3d()).WriteBinary(dir.File("sparse/0"));
  scene.Model({2, 3, 4}, colmap::Rigid3d()).WriteText(dir.File("sparse/1"));
  const std::vector<colmap::Reconstruction> models = ReadModels(dir.File("sparse"));
  ASSERT_EQ(models.size(), 2u);
  EXPECT_EQ(models[0].NumRegImages(), 3u);  // the text model, largest
  EXPECT_EQ(models[1].NumRegImages(), 2u);
  EXPECT_EQ(ReadModels(dir.File("sparse/1")).size(), 1u);
  std::filesystem::create_directories(dir.File("empty"));
  try {
    ReadModels(dir.File("empty"));
    FAIL() << "an empty folder was read as models";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(dir.File("empty")), std::string::npos);
  }
}

}  // namespace
}  // namespace colmap_lidar
