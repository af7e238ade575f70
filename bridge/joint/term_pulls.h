// How each data term pulls cam_from_lidar: at the optimum the terms' gradients balance, and a term's
// share of that balance is how far T_e would move, to first order, were the term left out. Terms
// that pull one axis apart by many sigmas (the reprojections one way, the LiDAR pairs the other)
// say that the sensors' data disagree beyond their noise: a sensor model error (the LiDAR's beam
// angles, the cameras' intrinsics, a clock offset) that no rigid cam_from_lidar absorbs.
#pragma once

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace colmap_lidar {

// One data term's pull on cam_from_lidar (rotation [deg] about, translation [mm] along the camera
// axes): -E^T H^-1 J_t^T r_t over the term's rows t (E selects T_e, H the joint problem's
// information), i.e. the estimate minus where the other terms would put it, to first order. It is
// the sum of its clusters' scores (those of the cluster-robust covariance); without a systematic
// error they scatter about zero, and the sum is compared with that scatter.
struct TermPull {
  std::string term;
  Eigen::Matrix<double, 6, 1> pull = Eigen::Matrix<double, 6, 1>::Zero();
  // pull / the reported sigma of each axis (0 on an undetermined axis)
  Eigen::Matrix<double, 6, 1> pull_sigmas = Eigen::Matrix<double, 6, 1>::Zero();
  // pull / the scatter of its clusters' shares (sqrt of the sum of their squares): how far the
  // pull lies beyond what the term's own noise explains, a t statistic
  Eigen::Matrix<double, 6, 1> significance = Eigen::Matrix<double, 6, 1>::Zero();
};

// Terms whose pulls on one axis are significant in opposite directions, each beyond this t,
// disagree.
constexpr double kTermDisagreementSignificance = 3.0;

// `pulls[k].pull_sigmas` from the reported covariance's diagonal; both it and the significance
// zero on undetermined axes.
void SetPullSigmas(const Eigen::Matrix<double, 6, 6>& covariance,
                   const std::array<bool, 6>& undetermined,
                   std::vector<TermPull>* pulls);

// One sentence per axis on which two terms pull apart, each beyond kTermDisagreementSignificance.
std::vector<std::string> DescribeTermDisagreements(const std::vector<TermPull>& pulls);

}  // namespace colmap_lidar
