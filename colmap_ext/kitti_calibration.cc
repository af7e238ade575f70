#include "colmap_ext/kitti_calibration.h"

#include "lidar/util/atomic_file.h"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

const std::vector<double>& Require(const std::map<std::string, std::vector<double>>& values,
                                   const std::string& key,
                                   size_t size,
                                   const std::string& path) {
  const auto it = values.find(key);
  if (it == values.end()) throw std::runtime_error(path + ": no " + key);
  if (it->second.size() != size) {
    throw std::runtime_error(path + ": " + key + " has " + std::to_string(it->second.size()) +
                             " values, not " + std::to_string(size));
  }
  return it->second;
}

// A line of numbers, or nothing when a token is not a finite number (calib_time's date).
bool ParseNumbers(const std::string& text, std::vector<double>* numbers) {
  std::istringstream tokens(text);
  std::string token;
  while (tokens >> token) {
    size_t used = 0;
    try {
      numbers->push_back(std::stod(token, &used));
    } catch (const std::exception&) {
      return false;
    }
    if (used != token.size() || !std::isfinite(numbers->back())) return false;
  }
  return true;
}

std::string Row(const double* values, int n) {
  std::ostringstream row;
  row << std::scientific << std::setprecision(15);
  for (int k = 0; k < n; ++k) row << (k ? " " : "") << values[k];
  return row.str();
}

std::string Key(const char* prefix, int index) {
  std::ostringstream key;
  key << prefix << std::setw(2) << std::setfill('0') << index;
  return key.str();
}

}  // namespace

std::map<std::string, std::vector<double>> ReadKittiCalibFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot open the KITTI calibration file " + path);
  std::map<std::string, std::vector<double>> values;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const size_t colon = line.find(':');
    if (colon == std::string::npos || colon == 0) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": not a 'key: values' line");
    }
    const std::string key = line.substr(0, colon);
    std::vector<double> numbers;
    if (ParseNumbers(line.substr(colon + 1), &numbers)) {
      values[key] = numbers;
    } else if (key.find("rect") != std::string::npos || key == "R" || key == "T" || key == "Tr" ||
               (key.size() == 2 && key[0] == 'P')) {
      // A key ReadKittiCamera needs, with a value that is not a finite number.
      throw std::runtime_error(path + ":" + std::to_string(number) + ": " + key +
                               " has a value that is not a finite number");
    }
  }
  return values;
}

namespace {

// A PINHOLE camera of the given size from a rectified projection P = K [I | K^-1 P[:,3]], placed by
// cam_from_velo = [I | K^-1 P[:,3]] * rect_from_velo.
KittiCamera CameraFromProjection(const Eigen::Matrix<double, 3, 4>& p,
                                 int index,
                                 int width,
                                 int height,
                                 const colmap::Rigid3d& rect_from_velo) {
  KittiCamera result;
  result.camera = colmap::Camera::CreateFromModelName(
      index + 1, "PINHOLE", p(0, 0), static_cast<size_t>(width), static_cast<size_t>(height));
  result.camera.params = {p(0, 0), p(1, 1), p(0, 2), p(1, 2)};
  result.projection_offset = p.leftCols<3>().inverse() * p.col(3);
  const colmap::Rigid3d offset(Eigen::Quaterniond::Identity(), result.projection_offset);
  result.cam_from_velo = offset * rect_from_velo;
  return result;
}

// A 3x3 block that is a rotation to KITTI's printed precision, as a unit quaternion.
Eigen::Quaterniond CheckedRotation(const Eigen::Matrix3d& r,
                                   const std::string& path,
                                   const std::string& key) {
  if (!(r.transpose() * r - Eigen::Matrix3d::Identity()).isZero(1e-4) || r.determinant() < 0) {
    throw std::runtime_error(path + ": " + key + " does not hold a rotation");
  }
  return Eigen::Quaterniond(r).normalized();
}

}  // namespace

KittiCamera ReadKittiCamera(const std::string& calib_dir, int index) {
  if (index < 0 || index > 3) throw std::invalid_argument("KITTI cameras are 0..3");
  const std::string cam_path = (fs::path(calib_dir) / "calib_cam_to_cam.txt").string();
  const std::string velo_path = (fs::path(calib_dir) / "calib_velo_to_cam.txt").string();
  const auto cam = ReadKittiCalibFile(cam_path);
  const auto velo = ReadKittiCalibFile(velo_path);
  const std::vector<double>& size = Require(cam, Key("S_rect_", index), 2, cam_path);
  const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> p(
      Require(cam, Key("P_rect_", index), 12, cam_path).data());
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r_rect(
      Require(cam, "R_rect_00", 9, cam_path).data());
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r(Require(velo, "R", 9, velo_path).data());
  const Eigen::Vector3d t(Require(velo, "T", 3, velo_path).data());
  if (!(p(0, 0) > 0) || !(p(1, 1) > 0) || !(size[0] >= 1) || !(size[1] >= 1)) {
    throw std::runtime_error(cam_path + ": " + Key("P_rect_", index) + "/" + Key("S_rect_", index) +
                             " give no valid pinhole camera");
  }
  const colmap::Rigid3d cam0_from_velo(Eigen::Quaterniond(Eigen::Matrix3d(r)).normalized(), t);
  const colmap::Rigid3d rect_from_cam0(Eigen::Quaterniond(Eigen::Matrix3d(r_rect)).normalized(),
                                       Eigen::Vector3d::Zero());
  return CameraFromProjection(p,
                              index,
                              static_cast<int>(size[0]),
                              static_cast<int>(size[1]),
                              rect_from_cam0 * cam0_from_velo);
}

KittiCamera ReadKittiOdometryCamera(const std::string& calib_file,
                                    int index,
                                    int width,
                                    int height) {
  if (index < 0 || index > 3) throw std::invalid_argument("KITTI cameras are 0..3");
  const auto calib = ReadKittiCalibFile(calib_file);
  const std::string key = "P" + std::to_string(index);
  const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> p(Require(calib, key, 12, calib_file).data());
  const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> tr(
      Require(calib, "Tr", 12, calib_file).data());
  if (!(p(0, 0) > 0) || !(p(1, 1) > 0) || width < 1 || height < 1) {
    throw std::runtime_error(calib_file + ": " + key + " gives no valid pinhole camera");
  }
  const colmap::Rigid3d rect_from_velo(CheckedRotation(tr.leftCols<3>(), calib_file, "Tr"),
                                       tr.col(3));
  return CameraFromProjection(p, index, width, height, rect_from_velo);
}

colmap::Rigid3d ReadKittiVeloFromImu(const std::string& calib_dir) {
  const std::string path = (fs::path(calib_dir) / "calib_imu_to_velo.txt").string();
  const auto values = ReadKittiCalibFile(path);
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r(Require(values, "R", 9, path).data());
  return colmap::Rigid3d(CheckedRotation(r, path, "R"),
                         Eigen::Vector3d(Require(values, "T", 3, path).data()));
}

colmap::Rigid3d KittiRightFromLeft(const KittiCamera& left, const KittiCamera& right) {
  return colmap::Rigid3d(Eigen::Quaterniond::Identity(),
                         right.projection_offset - left.projection_offset);
}

void WriteKittiCalibration(const std::string& calib_dir, const KittiCalibrationFiles& files) {
  fs::create_directories(calib_dir);
  std::ostringstream cam;
  cam << "calib_time: 01-Jan-2026 00:00:00\ncorner_dist: 9.950000e-02\n";
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r_rect = files.r_rect_00;
  for (size_t i = 0; i < files.p_rect.size(); ++i) {
    const int index = static_cast<int>(i);
    const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> p = files.p_rect[i];
    const double size[2] = {double(files.width), double(files.height)};
    cam << Key("S_rect_", index) << ": " << Row(size, 2) << "\n";
    if (i == 0) cam << "R_rect_00: " << Row(r_rect.data(), 9) << "\n";
    cam << Key("P_rect_", index) << ": " << Row(p.data(), 12) << "\n";
  }
  WriteFileAtomically((fs::path(calib_dir) / "calib_cam_to_cam.txt").string(), cam.str());
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r =
      files.cam0_from_velo.rotation.toRotationMatrix();
  std::ostringstream velo;
  velo << "calib_time: 01-Jan-2026 00:00:00\nR: " << Row(r.data(), 9)
       << "\nT: " << Row(files.cam0_from_velo.translation.data(), 3)
       << "\ndelta_f: 0.000000e+00 0.000000e+00\ndelta_c: 0.000000e+00 0.000000e+00\n";
  WriteFileAtomically((fs::path(calib_dir) / "calib_velo_to_cam.txt").string(), velo.str());
}

}  // namespace colmap_lidar
