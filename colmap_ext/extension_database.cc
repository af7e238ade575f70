#include "colmap_ext/extension_database.h"

#include "colmap_ext/logging.h"

#include "colmap/sensor/models.h"

#include <stdexcept>

namespace colmap_lidar {
namespace {

void BindRigid3d(SqliteStatement* stmt,
                 int first_index,
                 const colmap::Rigid3d& target_from_source) {
  const Eigen::Quaterniond& q = target_from_source.rotation;
  const Eigen::Vector3d& t = target_from_source.translation;
  const double values[7] = {q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z()};
  for (int i = 0; i < 7; ++i) stmt->BindDouble(first_index + i, values[i]);
}

colmap::Rigid3d ColumnRigid3d(const SqliteStatement& stmt, int first_column) {
  colmap::Rigid3d target_from_source;
  target_from_source.rotation = Eigen::Quaterniond(stmt.ColumnDouble(first_column),
                                                   stmt.ColumnDouble(first_column + 1),
                                                   stmt.ColumnDouble(first_column + 2),
                                                   stmt.ColumnDouble(first_column + 3))
                                    .normalized();
  target_from_source.translation = Eigen::Vector3d(stmt.ColumnDouble(first_column + 4),
                                                   stmt.ColumnDouble(first_column + 5),
                                                   stmt.ColumnDouble(first_column + 6));
  return target_from_source;
}

std::string RigidColumns(const std::string& prefix, const std::string& type) {
  std::string sql;
  for (const char* c : {"qw", "qx", "qy", "qz", "tx", "ty", "tz"}) {
    sql += ", " + prefix + "_" + c + " " + type;
  }
  return sql;
}

}  // namespace

ExtensionDatabase::ExtensionDatabase(const std::string& path, Mode mode, int busy_timeout_ms)
    : connection_(path, mode, busy_timeout_ms) {
  if (!connection_.TableExists("images") || !connection_.TableExists("cameras")) {
    throw std::runtime_error("Not a COLMAP database (no 'images'/'cameras' tables): " + path +
                             ". Create it with `colmap database_creator` or "
                             "`colmap-lidar database_creator` first.");
  }
  if (mode == Mode::kReadWrite && !HasOurTables()) CreateTables();
}

bool ExtensionDatabase::HasOurTables() const {
  return connection_.TableExists("depth_priors") && connection_.TableExists("lidar_frames") &&
         connection_.TableExists("rig");
}

void ExtensionDatabase::CreateTables() {
  SqliteTransaction transaction(connection_);
  connection_.Execute(
      "CREATE TABLE IF NOT EXISTS depth_priors("
      "image_id INTEGER NOT NULL,"
      "point2D_idx INTEGER NOT NULL CHECK(point2D_idx >= 0),"
      "depth REAL NOT NULL CHECK(depth > 0),"
      "sigma REAL NOT NULL CHECK(sigma > 0),"
      "PRIMARY KEY(image_id, point2D_idx),"
      "FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE)");
  connection_.Execute(
      "CREATE TABLE IF NOT EXISTS lidar_frames("
      "frame_id INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL,"
      "image_id INTEGER NOT NULL UNIQUE,"
      "path TEXT NOT NULL" +
      RigidColumns("cam_from_lidar_guess", "REAL") +
      ", FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE "
      "CASCADE)");
  connection_.Execute(
      "CREATE TABLE IF NOT EXISTS rig("
      "rig_id INTEGER PRIMARY KEY NOT NULL CHECK(rig_id = 1),"
      "left_camera_id INTEGER NOT NULL,"
      "right_model TEXT NOT NULL,"
      "right_width INTEGER NOT NULL CHECK(right_width > 0),"
      "right_height INTEGER NOT NULL CHECK(right_height > 0),"
      "right_params BLOB NOT NULL" +
      RigidColumns("right_from_left", "REAL NOT NULL") +
      ", FOREIGN KEY(left_camera_id) REFERENCES cameras(camera_id) ON DELETE "
      "CASCADE)");
  transaction.Commit();
}

void ExtensionDatabase::WriteDepthPriors(colmap::image_t image_id,
                                         const std::vector<DepthPrior>& priors) {
  WriteDepthPriors({{image_id, priors}});
}

void ExtensionDatabase::WriteDepthPriors(
    const std::map<colmap::image_t, std::vector<DepthPrior>>& priors_per_image) {
  SqliteTransaction transaction(connection_);
  SqliteStatement remove(connection_, "DELETE FROM depth_priors WHERE image_id=?");
  SqliteStatement insert(connection_,
                         "INSERT INTO depth_priors(image_id, point2D_idx, depth, sigma) "
                         "VALUES(?, ?, ?, ?)");
  for (const auto& [image_id, priors] : priors_per_image) {
    remove.Reset();
    remove.BindInt64(1, image_id);
    remove.Execute();
    for (const DepthPrior& prior : priors) {
      insert.Reset();
      insert.BindInt64(1, image_id);
      insert.BindInt64(2, prior.point2D_idx);
      insert.BindDouble(3, prior.depth);
      insert.BindDouble(4, prior.sigma);
      insert.Execute();
    }
  }
  transaction.Commit();
}

std::vector<DepthPrior> ExtensionDatabase::ReadDepthPriors(colmap::image_t image_id) const {
  std::vector<DepthPrior> priors;
  if (!HasOurTables()) return priors;
  SqliteStatement select(connection_,
                         "SELECT point2D_idx, depth, sigma FROM depth_priors "
                         "WHERE image_id=? ORDER BY point2D_idx");
  select.BindInt64(1, image_id);
  while (select.Step()) {
    DepthPrior prior;
    prior.point2D_idx = static_cast<colmap::point2D_t>(select.ColumnInt64(0));
    prior.depth = select.ColumnDouble(1);
    prior.sigma = select.ColumnDouble(2);
    priors.push_back(prior);
  }
  return priors;
}

size_t ExtensionDatabase::NumDepthPriors() const {
  if (!HasOurTables()) return 0;
  SqliteStatement count(connection_, "SELECT count(*) FROM depth_priors");
  count.Step();
  return static_cast<size_t>(count.ColumnInt64(0));
}

void ExtensionDatabase::ClearDepthPriors() {
  SqliteTransaction transaction(connection_);
  connection_.Execute("DELETE FROM depth_priors");
  transaction.Commit();
}

int64_t ExtensionDatabase::WriteLidarFrame(const LidarFrame& frame) {
  THROW_CHECK(!frame.path.empty()) << "LiDAR frame without a cloud path";
  SqliteTransaction transaction(connection_);
  SqliteStatement upsert(connection_,
                         "INSERT INTO lidar_frames(image_id, path" +
                             RigidColumns("cam_from_lidar_guess", "") +
                             ") VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?) "
                             "ON CONFLICT(image_id) DO UPDATE SET path=excluded.path, "
                             "cam_from_lidar_guess_qw=excluded.cam_from_lidar_guess_qw, "
                             "cam_from_lidar_guess_qx=excluded.cam_from_lidar_guess_qx, "
                             "cam_from_lidar_guess_qy=excluded.cam_from_lidar_guess_qy, "
                             "cam_from_lidar_guess_qz=excluded.cam_from_lidar_guess_qz, "
                             "cam_from_lidar_guess_tx=excluded.cam_from_lidar_guess_tx, "
                             "cam_from_lidar_guess_ty=excluded.cam_from_lidar_guess_ty, "
                             "cam_from_lidar_guess_tz=excluded.cam_from_lidar_guess_tz");
  upsert.BindInt64(1, frame.image_id);
  upsert.BindText(2, frame.path);
  if (frame.cam_from_lidar_guess) {
    BindRigid3d(&upsert, 3, *frame.cam_from_lidar_guess);
  } else {
    for (int i = 3; i < 10; ++i) upsert.BindNull(i);
  }
  upsert.Execute();
  SqliteStatement select(connection_, "SELECT frame_id FROM lidar_frames WHERE image_id=?");
  select.BindInt64(1, frame.image_id);
  THROW_CHECK(select.Step());
  const int64_t frame_id = select.ColumnInt64(0);
  transaction.Commit();
  return frame_id;
}

std::vector<LidarFrame> ExtensionDatabase::ReadLidarFrames() const {
  std::vector<LidarFrame> frames;
  if (!HasOurTables()) return frames;
  SqliteStatement select(connection_,
                         "SELECT frame_id, image_id, path" +
                             RigidColumns("cam_from_lidar_guess", "") +
                             " FROM lidar_frames ORDER BY frame_id");
  while (select.Step()) {
    LidarFrame frame;
    frame.frame_id = select.ColumnInt64(0);
    frame.image_id = static_cast<colmap::image_t>(select.ColumnInt64(1));
    frame.path = select.ColumnText(2);
    if (!select.ColumnIsNull(3)) {
      frame.cam_from_lidar_guess = ColumnRigid3d(select, 3);
    }
    frames.push_back(std::move(frame));
  }
  return frames;
}

std::optional<LidarFrame> ExtensionDatabase::ReadLidarFrameOfImage(colmap::image_t image_id) const {
  for (LidarFrame& frame : ReadLidarFrames()) {
    if (frame.image_id == image_id) return std::move(frame);
  }
  return std::nullopt;
}

void ExtensionDatabase::WriteRig(const StereoRig& rig) {
  const colmap::Camera& right = rig.right_camera;
  THROW_CHECK(right.VerifyParams())
      << "Right camera parameters do not fit model " << right.ModelName();
  THROW_CHECK_GT(rig.BaselineMeters(), 0) << "Stereo rig with zero baseline";
  SqliteTransaction transaction(connection_);
  SqliteStatement upsert(connection_,
                         "INSERT OR REPLACE INTO rig(rig_id, left_camera_id, right_model, "
                         "right_width, right_height, right_params" +
                             RigidColumns("right_from_left", "") +
                             ") VALUES(1, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  upsert.BindInt64(1, rig.left_camera_id);
  upsert.BindText(2, right.ModelName());
  upsert.BindInt64(3, static_cast<int64_t>(right.width));
  upsert.BindInt64(4, static_cast<int64_t>(right.height));
  upsert.BindBlob(5, right.params.data(), static_cast<int>(right.params.size() * sizeof(double)));
  BindRigid3d(&upsert, 6, rig.right_from_left);
  upsert.Execute();
  transaction.Commit();
}

std::optional<StereoRig> ExtensionDatabase::ReadRig() const {
  if (!HasOurTables()) return std::nullopt;
  SqliteStatement select(connection_,
                         "SELECT left_camera_id, right_model, right_width, "
                         "right_height, right_params" +
                             RigidColumns("right_from_left", "") + " FROM rig WHERE rig_id=1");
  if (!select.Step()) return std::nullopt;
  StereoRig rig;
  rig.left_camera_id = static_cast<colmap::camera_t>(select.ColumnInt64(0));
  const std::string model = select.ColumnText(1);
  if (!colmap::ExistsCameraModelWithName(model)) {
    throw std::runtime_error("Unknown camera model '" + model + "' in table rig of " + Path());
  }
  rig.right_camera.model_id = colmap::CameraModelNameToId(model);
  rig.right_camera.width = static_cast<size_t>(select.ColumnInt64(2));
  rig.right_camera.height = static_cast<size_t>(select.ColumnInt64(3));
  rig.right_camera.params = select.ColumnDoubleBlob(4);
  rig.right_from_left = ColumnRigid3d(select, 5);
  return rig;
}

}  // namespace colmap_lidar
