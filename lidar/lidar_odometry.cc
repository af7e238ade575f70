#include "lidar/lidar_odometry.h"

#include "lidar/util/check_option.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <stdexcept>

namespace colmap_lidar {
namespace {

// KISS-ICP's subsampling factors of the voxel size: map points and registration points.
constexpr double kMapVoxelFactor = 0.5;
constexpr double kSourceVoxelFactor = 1.5;

// Graduated non-convexity for the frame without a predicted motion: the Geman-McClure kernel's
// scale in units of the threshold's sigma, stage by stage, each from the last stage's pose; the
// final stage is every frame's kernel sigma / 3.
constexpr double kStartKernelFactors[] = {3.0, 1.0};

std::vector<Eigen::Vector3d> Transformed(const Eigen::Isometry3d& pose,
                                         const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const Eigen::Vector3d& p : points) out.push_back(pose * p);
  return out;
}

// How well the frame's translation is held once its rotation is free: the Schur complement
// H_tt - H_tr H_rr^-1 H_rt of the information [omega, t], its smallest over largest eigenvalue and
// the direction of the smallest (a street of bare facades: along the street).
ConstraintAnalysis TranslationConstraints(const Eigen::Matrix<double, 6, 6>& information) {
  ConstraintAnalysis analysis;
  const Eigen::Matrix3d rotation = information.topLeftCorner<3, 3>();
  if (!(rotation.determinant() > 0)) {
    // Too few planes to hold the rotation: the weakest direction of the whole information.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> solver(information);
    analysis.weakest_direction = solver.eigenvectors().col(0);
    return analysis;
  }
  const Eigen::Matrix3d schur = information.bottomRightCorner<3, 3>() -
                                information.bottomLeftCorner<3, 3>() * rotation.inverse() *
                                    information.topRightCorner<3, 3>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(schur);
  if (!(solver.eigenvalues()(2) > 0)) return analysis;
  analysis.weakest_ratio = std::max(solver.eigenvalues()(0), 0.0) / solver.eigenvalues()(2);
  analysis.weakest_direction.tail<3>() = solver.eigenvectors().col(0);
  return analysis;
}

}  // namespace

Eigen::Isometry3d ScaleMotion(const Eigen::Isometry3d& motion, double fraction) {
  const Eigen::AngleAxisd rotation(motion.rotation());
  Eigen::Isometry3d scaled = Eigen::Isometry3d::Identity();
  scaled.linear() =
      Eigen::AngleAxisd(fraction * rotation.angle(), rotation.axis()).toRotationMatrix();
  scaled.translation() = fraction * motion.translation();
  return scaled;
}

bool LidarOdometryOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(max_range_m, 0);
  LIDAR_CHECK_OPTION_GE(min_range_m, 0);
  LIDAR_CHECK_OPTION_LT(min_range_m, max_range_m);
  LIDAR_CHECK_OPTION_GE(voxel_size_m, 0);
  LIDAR_CHECK_OPTION_GT(max_points_per_voxel, 0);
  LIDAR_CHECK_OPTION_GT(initial_sigma_m, 0);
  LIDAR_CHECK_OPTION_GE(min_motion_m, 0);
  LIDAR_CHECK_OPTION_GT(degenerate_ratio, 0);
  LIDAR_CHECK_OPTION_LT(degenerate_ratio, 1);
  return timing.Check() && icp.Check();
}

LidarOdometry::LidarOdometry(const LidarOdometryOptions& options)
    : options_((ThrowUnlessValid(options, "LidarOdometryOptions"), options)),
      map_(options.VoxelSize(), options.max_range_m, options.max_points_per_voxel),
      threshold_(options.initial_sigma_m, options.min_motion_m, options.max_range_m) {}

std::vector<Eigen::Vector3d> LidarOdometry::Preprocess(const PointCloud& sweep) const {
  const bool deskew = options_.deskew && frames_.size() >= 2;
  PointCloud in_range;
  in_range.points.reserve(sweep.Size());
  for (size_t i = 0; i < sweep.Size(); ++i) {
    const double range = sweep.points[i].norm();
    if (range < options_.min_range_m || range > options_.max_range_m) continue;
    in_range.points.push_back(sweep.points[i]);
    if (deskew && sweep.HasTimes()) in_range.times.push_back(sweep.times[i]);
  }
  if (!deskew || in_range.Empty()) return std::move(in_range.points);
  SweepMotion motion;
  motion.mid_from_next_mid = velocity_;
  motion.mid_from_previous_mid = velocity_.inverse();
  return DeskewSweep(in_range, motion, options_.timing).points;
}

void LidarOdometry::FinishFrame(const FrameToMapIcpResult& icp, OdometryFrame* frame) const {
  frame->world_from_lidar = icp.world_from_lidar;
  frame->converged = icp.converged;
  frame->num_iterations = icp.num_iterations;
  frame->num_correspondences = icp.num_correspondences;
  frame->rms_m = icp.rms_m;
  frame->plane_rms_m = icp.plane_rms_m;
  frame->information = icp.information;
  frame->constraints = TranslationConstraints(icp.information);
  frame->degenerate = frame->constraints.weakest_ratio < options_.degenerate_ratio;
  if (!frame->degenerate) {
    frame->covariance = icp.plane_rms_m * icp.plane_rms_m * icp.information.inverse();
  }
}

const OdometryFrame& LidarOdometry::RegisterFrame(const std::vector<Eigen::Vector3d>& points,
                                                  double clock) {
  PointCloud sweep;
  sweep.points = points;
  return RegisterFrame(sweep, clock);
}

const OdometryFrame& LidarOdometry::RegisterFrame(const PointCloud& sweep, double clock) {
  if (!frames_.empty() && !(clock > last_clock_)) {
    throw std::invalid_argument("LidarOdometry: frame clock " + std::to_string(clock) +
                                " does not follow " + std::to_string(last_clock_));
  }
  OdometryFrame frame;
  const std::vector<Eigen::Vector3d> deskewed = Preprocess(sweep);
  if (deskewed.empty()) throw std::runtime_error("no point within the LiDAR's range");
  frame.num_points = deskewed.size();
  const double voxel = options_.VoxelSize();
  const std::vector<Eigen::Vector3d> map_points =
      FirstPointPerVoxel(deskewed, kMapVoxelFactor * voxel);
  const std::vector<Eigen::Vector3d> source =
      FirstPointPerVoxel(map_points, kSourceVoxelFactor * voxel);
  frame.num_source_points = source.size();
  if (frames_.empty()) {
    frame.converged = true;
  } else {
    const Eigen::Isometry3d& last = frames_.back().world_from_lidar;
    frame.prediction = last * ScaleMotion(velocity_, clock - last_clock_);
    const double sigma = threshold_.Sigma();
    frame.threshold_m = 3.0 * sigma;
    Eigen::Isometry3d start = frame.prediction;
    if (frames_.size() == 1) {
      for (const double factor : kStartKernelFactors) {
        start = AlignFrameToMap(source, &map_, start, 3.0 * sigma, factor * sigma, options_.icp)
                    .world_from_lidar;
      }
    }
    FinishFrame(AlignFrameToMap(source, &map_, start, 3.0 * sigma, sigma / 3.0, options_.icp),
                &frame);
    const Eigen::Isometry3d motion = last.inverse() * frame.world_from_lidar;
    threshold_.Update(frame.prediction.inverse() * frame.world_from_lidar, motion);
    velocity_ = ScaleMotion(motion, 1.0 / (clock - last_clock_));
  }
  map_.Update(Transformed(frame.world_from_lidar, map_points),
              frame.world_from_lidar.translation());
  last_clock_ = clock;
  frames_.push_back(frame);
  return frames_.back();
}

}  // namespace colmap_lidar
