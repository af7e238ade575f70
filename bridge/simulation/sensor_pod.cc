#include "bridge/simulation/sensor_pod.h"

#include "colmap/sensor/models.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace colmap_lidar {
namespace sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// world_from_cam rotation of a camera with heading `yaw` (angle of the optical axis in the ground
// plane, from world x towards y), pitched up by `pitch` and rolled by `roll` about its optical axis.
Eigen::Matrix3d WorldFromCamRotation(double yaw, double pitch, double roll) {
  const Eigen::Vector3d forward(
      std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch));
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d world_from_cam;
  world_from_cam << right, down, forward;
  return world_from_cam * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

colmap::Rigid3d CamFromWorld(const Eigen::Matrix3d& world_from_cam, const Eigen::Vector3d& center) {
  const Eigen::Matrix3d cam_from_world = world_from_cam.transpose();
  return colmap::Rigid3d(Eigen::Quaterniond(cam_from_world), -cam_from_world * center);
}

}  // namespace

bool IsDrive(Motion motion) {
  return motion == Motion::kDrive || motion == Motion::kDriveReturn ||
         motion == Motion::kStraightDrive;
}

namespace {

// A simulated stereo pod: two identical PINHOLE cameras with a horizontal field of view, the right
// one `baseline_m` to the right and turned by `misalignment_deg` about a generic axis (a real bar is
// never perfectly parallel), and its LiDAR's model name.
struct PodModel {
  double width_px;
  double height_px;
  double horizontal_fov_deg;
  double baseline_m;
  double misalignment_deg;
  Eigen::Vector3d misalignment_axis;
  std::string lidar_model;
};

StationRig MakePinholePair(const PodModel& pod) {
  const size_t width = static_cast<size_t>(std::lround(pod.width_px));
  const size_t height = static_cast<size_t>(std::lround(pod.height_px));
  const double focal = 0.5 * width / std::tan(0.5 * pod.horizontal_fov_deg * kDegToRad);
  StationRig rig;
  rig.left = colmap::Camera::CreateFromModelName(
      colmap::kInvalidCameraId, "PINHOLE", focal, width, height);
  rig.right = rig.left;
  rig.right_from_left.rotation = Eigen::Quaterniond(
      Eigen::AngleAxisd(pod.misalignment_deg * kDegToRad, pod.misalignment_axis.normalized()));
  rig.right_from_left.translation = Eigen::Vector3d(-pod.baseline_m, 0.0, 0.0);
  rig.lidar_model = pod.lidar_model;
  return rig;
}

}  // namespace

StationRig MakeStereoRig(double image_scale) {
  return MakePinholePair({1028 * image_scale,
                          752 * image_scale,
                          48,
                          0.38,
                          0.15,
                          Eigen::Vector3d(0.2, 1, 0.1),
                          "VLP-16"});
}

StationRig MakeDriveRig(double image_scale) {
  return MakePinholePair({1242 * image_scale,
                          375 * image_scale,
                          90,
                          0.54,
                          0.1,
                          Eigen::Vector3d(0.1, 1, 0.2),
                          "HDL-64"});
}

colmap::Rigid3d TrueCamFromLidar() {
  // LiDAR axes (x forward, y left, z up) expressed in the camera (x right, y down, z forward)...
  Eigen::Matrix3d cam_from_lidar_axes;
  cam_from_lidar_axes << 0, -1, 0,  //
      0, 0, -1,                     //
      1, 0, 0;
  // ... with a generic mounting error of a few degrees.
  const Eigen::Matrix3d misalignment =
      (Eigen::AngleAxisd(1.5 * kDegToRad, Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(-2.0 * kDegToRad, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(2.5 * kDegToRad, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  // The LiDAR's origin in the camera frame: 0.19 m right (mid-baseline), 0.25 m up, 0.05 m back.
  return colmap::Rigid3d(Eigen::Quaterniond(cam_from_lidar_axes * misalignment),
                         Eigen::Vector3d(0.19, -0.25, -0.05));
}

colmap::Rigid3d CamLookingAt(const Eigen::Vector3d& eye,
                             const Eigen::Vector3d& target,
                             double roll_deg) {
  const Eigen::Vector3d d = target - eye;
  return CamFromWorld(
      WorldFromCamRotation(
          std::atan2(d.y(), d.x()), std::atan2(d.z(), d.head<2>().norm()), roll_deg * kDegToRad),
      eye);
}

namespace {

// The return drive's lanes: out along y = -1.8 m, back along y = +1.8 m.
constexpr double kReturnLane = 1.8;

// Heading at path length s of the return drive whose turn starts at `length` and is `turn` long:
// 0 out, pi back; in the turn the curvature rises and falls as sin^2 (a driver steering in and out
// of a U-turn), so that the heading is pi (u - sin(2 pi u) / (2 pi)) at the turn's fraction u.
double ReturnHeading(double s, double length, double turn) {
  const double u = std::clamp((s - length) / turn, 0.0, 1.0);
  return M_PI * (u - std::sin(2 * M_PI * u) / (2 * M_PI));
}

// The turn's length that takes the car from one lane to the other (the lateral offset of the
// turn scales with its length).
double ReturnTurnLength() {
  constexpr int kSteps = 10000;
  double offset_per_metre = 0;
  for (int k = 0; k < kSteps; ++k) {
    offset_per_metre += std::sin(ReturnHeading((k + 0.5) / kSteps, 0, 1)) / kSteps;
  }
  return 2 * kReturnLane / offset_per_metre;
}

// The step at path length s: 1.0-1.5 m per frame (`unit` in [0, 1)), slowing to a quarter within
// 4 m of the turn (a platform that turns around at walking pace).
double ReturnStep(double s, double length, double turn, double unit) {
  const double to_turn = std::max({0.0, length - s, s - length - turn});
  return (1.0 + 0.5 * unit) * (0.25 + 0.75 * std::min(1.0, to_turn / 4.0));
}

// Out along one lane, a U-turn at the far end, back along the other lane; the way's straight part
// such that the frames at their mean step cover it. Heading along the path.
std::vector<colmap::Rigid3d> ReturnDriveStations(int num_stations, std::mt19937_64* rng) {
  const double turn = ReturnTurnLength();
  const auto frames_to_cover = [turn](double length) {
    int frames = 1;
    for (double s = 0; s < 2 * length + turn; ++frames) s += ReturnStep(s, length, turn, 0.5);
    return frames;
  };
  double length = 0;
  while (frames_to_cover(length + 0.5) <= num_stations) length += 0.5;
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<colmap::Rigid3d> stations;
  Eigen::Vector2d position(0, -kReturnLane);
  double s = 0;  // path length
  for (int i = 0; i < num_stations; ++i) {
    const double heading = ReturnHeading(s, length, turn);
    stations.push_back(CamFromWorld(WorldFromCamRotation(heading, 0, 0),
                                    Eigen::Vector3d(position.x(), position.y(), 1.65)));
    const double step = ReturnStep(s, length, turn, unit(*rng));
    constexpr int kSubsteps = 100;
    for (int k = 0; k < kSubsteps; ++k) {
      const double h = ReturnHeading(s + (k + 0.5) * step / kSubsteps, length, turn);
      position += step / kSubsteps * Eigen::Vector2d(std::cos(h), std::sin(h));
    }
    s += step;
  }
  return stations;
}

// 0.5-1 m per frame, heading along the path y = lateral(x); with `turns` a lane change (1.6 m over
// ~25 m) and a swerve, without them the right lane's centre.
std::vector<colmap::Rigid3d> DriveStations(int num_stations, bool turns, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0, 1);
  auto lateral = [turns](double x) {
    return turns ? 1.6 / (1 + std::exp(-(x - 20) / 4)) - 1.8 + 0.4 * std::sin(x / 9) : -1.8;
  };
  std::vector<colmap::Rigid3d> stations;
  double x = 0;
  for (int i = 0; i < num_stations; ++i) {
    const double slope = (lateral(x + 0.5) - lateral(x - 0.5));
    stations.push_back(CamFromWorld(WorldFromCamRotation(std::atan(slope), 0, 0),
                                    Eigen::Vector3d(x, lateral(x), 1.65)));
    x += 0.5 + 0.5 * unit(*rng);
  }
  return stations;
}

// A line of stations in front of the structure, all with the same orientation.
std::vector<colmap::Rigid3d> FixedRotationStations(const Scene& scene,
                                                   int num_stations,
                                                   double pitch,
                                                   std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0, 1);
  const Eigen::Vector3d& c = scene.ObjectCenter();
  const double yaw = M_PI / 2;  // looking along +y from the -y side
  const Eigen::Matrix3d world_from_cam = WorldFromCamRotation(yaw, pitch, 0);
  const double distance = scene.ObjectRadius() + 2.3;
  std::vector<colmap::Rigid3d> stations;
  for (int i = 0; i < num_stations; ++i) {
    const double s = -1.2 + 2.4 * i / (num_stations - 1);
    const Eigen::Vector3d center(
        c.x() + s, c.y() - distance + 0.3 * unit(*rng), 1.1 + 0.2 * unit(*rng));
    stations.push_back(CamFromWorld(world_from_cam, center));
  }
  return stations;
}

}  // namespace

std::vector<colmap::Rigid3d> MakeStations(const Scene& scene,
                                          int num_stations,
                                          Motion motion,
                                          uint64_t seed) {
  if (num_stations < 2) throw std::invalid_argument("Need at least 2 stations");
  std::mt19937_64 rng(seed ^ 0x5eed);
  std::uniform_real_distribution<double> unit(0, 1);
  const Eigen::Vector3d& c = scene.ObjectCenter();
  const double look_height = std::min(1.2, 0.5 * scene.ObjectHeight());
  const double ring_pitch = -4 * kDegToRad;  // the same for all tripod stations
  std::vector<colmap::Rigid3d> stations;

  if (motion == Motion::kDriveReturn) return ReturnDriveStations(num_stations, &rng);
  if (motion == Motion::kDrive) return DriveStations(num_stations, /*turns=*/true, &rng);
  if (motion == Motion::kStraightDrive) {
    return DriveStations(num_stations, /*turns=*/false, &rng);
  }
  if (motion == Motion::kFixedRotation) {
    return FixedRotationStations(scene, num_stations, ring_pitch, &rng);
  }

  // About a fifth of the stations tilted (at least one), never more than half.
  const int num_tilted = motion == Motion::kTwoAxes
                             ? std::min(std::max(1, (num_stations + 2) / 5), num_stations / 2)
                             : 0;
  const int num_ring = num_stations - num_tilted;
  auto ring_azimuth = [&](double k) { return 2 * M_PI * k / num_ring - M_PI / 2; };
  for (int i = 0; i < num_ring; ++i) {
    const double azimuth = ring_azimuth(i);  // position of the station around the structure
    const double distance = scene.ObjectRadius() + 2.0 + 0.8 * unit(rng);
    const Eigen::Vector3d center =
        c + distance * Eigen::Vector3d(std::cos(azimuth), std::sin(azimuth), 0);
    const Eigen::Vector3d eye(
        center.x(), center.y(), look_height + distance * std::tan(-ring_pitch));
    const double yaw = azimuth + M_PI + 0.06 * (unit(rng) - 0.5);
    stations.push_back(CamFromWorld(WorldFromCamRotation(yaw, ring_pitch, 0), eye));
  }
  // Stations tilted up from near the ground, between the tripod ones, with alternating roll.
  for (int i = 0; i < num_tilted; ++i) {
    const double azimuth = ring_azimuth((i + 0.5) * num_ring / double(num_tilted));
    const double distance = scene.ObjectRadius() + 2.2 + 0.5 * unit(rng);
    const Eigen::Vector3d eye =
        c + distance * Eigen::Vector3d(std::cos(azimuth), std::sin(azimuth), 0);
    const double pitch = std::atan2(look_height - 0.45, distance) + (8 + 6 * unit(rng)) * kDegToRad;
    const double roll = (i % 2 ? 1 : -1) * (6 + 4 * unit(rng)) * kDegToRad;
    stations.push_back(CamFromWorld(WorldFromCamRotation(azimuth + M_PI, pitch, roll),
                                    Eigen::Vector3d(eye.x(), eye.y(), 0.45)));
  }
  for (const colmap::Rigid3d& station : stations) {
    if (!station.translation.allFinite() || !station.rotation.coeffs().allFinite()) {
      throw std::logic_error("Simulator produced a non-finite station pose");
    }
  }
  return stations;
}

}  // namespace sim
}  // namespace colmap_lidar
