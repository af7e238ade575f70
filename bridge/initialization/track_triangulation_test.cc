#include "bridge/initialization/track_triangulation.h"

#include "tests/testing/scoped_temp_dir.h"

#include "colmap/scene/database.h"
#include "colmap/scene/synthetic.h"

#include <gtest/gtest.h>

namespace colmap_lidar {
namespace {

// COLMAP's synthetic scene (exact keypoints, every observation pair matched) and its database.
struct SyntheticScene {
  testing::ScopedTempDir dir;
  std::string database_path = dir.File("database.db");
  colmap::Reconstruction truth;

  SyntheticScene() {
    colmap::SyntheticDatasetOptions options;
    options.num_cameras = 1;
    options.num_images = 8;
    options.num_points3D = 200;
    colmap::Database database(database_path);
    colmap::SynthesizeDataset(options, &truth, &database);
  }

  std::map<colmap::image_t, colmap::Rigid3d> Poses() const {
    std::map<colmap::image_t, colmap::Rigid3d> poses;
    for (const colmap::image_t image_id : truth.RegImageIds()) {
      poses[image_id] = truth.Image(image_id).CamFromWorld();
    }
    return poses;
  }
  std::map<colmap::camera_t, colmap::Camera> Cameras() const {
    return {truth.Cameras().begin(), truth.Cameras().end()};
  }
};

size_t NumObservations(const colmap::Reconstruction& model) {
  size_t observations = 0;
  for (const auto& [point3D_id, point3D] : model.Points3D()) observations += point3D.track.Length();
  return observations;
}

TEST(TrackTriangulation, RebuildsTheTrueTracksAtTheTruePoses) {
  const SyntheticScene scene;
  const std::shared_ptr<colmap::Reconstruction> model =
      TriangulateAtPoses(scene.database_path, scene.Cameras(), scene.Poses());
  EXPECT_EQ(model->NumRegImages(), scene.truth.NumRegImages());
  EXPECT_EQ(model->NumPoints3D(), scene.truth.NumPoints3D());
  EXPECT_EQ(FractionOfObservationsRetracked(scene.truth, *model), 0.0);
  for (const colmap::image_t image_id : model->RegImageIds()) {
    const colmap::Rigid3d& pose = model->Image(image_id).CamFromWorld();
    EXPECT_LT((pose.translation - scene.truth.Image(image_id).CamFromWorld().translation).norm(),
              1e-12);
  }
}

TEST(TrackTriangulation, RetriangulatingReplacesTheLandmarksAndKeepsThePoses) {
  const SyntheticScene scene;
  colmap::Reconstruction model = scene.truth;
  // A wrong partition: two landmarks' observations merged into one track.
  const std::vector<colmap::point3D_t> ids = [&] {
    std::vector<colmap::point3D_t> all;
    for (const auto& [id, point3D] : model.Points3D()) all.push_back(id);
    return all;
  }();
  model.MergePoints3D(ids[0], ids[1]);
  EXPECT_GT(FractionOfObservationsRetracked(scene.truth, model), 0.0);
  RetriangulateTracks(scene.database_path, &model);
  EXPECT_EQ(FractionOfObservationsRetracked(scene.truth, model), 0.0);
  EXPECT_EQ(model.NumRegImages(), scene.truth.NumRegImages());
}

TEST(TrackTriangulation, CountsEveryObservationOfAChangedTrack) {
  const SyntheticScene scene;
  EXPECT_EQ(FractionOfObservationsRetracked(scene.truth, scene.truth), 0.0);
  colmap::Reconstruction after = scene.truth;
  const auto& [point3D_id, point3D] = *scene.truth.Points3D().begin();
  const colmap::TrackElement removed = point3D.track.Element(0);
  after.DeleteObservation(removed.image_id, removed.point2D_idx);
  EXPECT_DOUBLE_EQ(FractionOfObservationsRetracked(scene.truth, after),
                   static_cast<double>(point3D.track.Length()) / NumObservations(scene.truth));
  EXPECT_EQ(FractionOfObservationsRetracked(colmap::Reconstruction(), after), 0.0);
}

}  // namespace
}  // namespace colmap_lidar
