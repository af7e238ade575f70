#include "bridge/joint/term_pulls.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace colmap_lidar {
namespace {

constexpr const char* kAxisNames[6] = {"rotation about the camera x axis",
                                       "rotation about the camera y axis",
                                       "rotation about the camera z axis",
                                       "translation along the camera x axis",
                                       "translation along the camera y axis",
                                       "translation along the camera z axis"};

}  // namespace

void SetPullSigmas(const Eigen::Matrix<double, 6, 6>& covariance,
                   const std::array<bool, 6>& undetermined,
                   std::vector<TermPull>* pulls) {
  for (TermPull& pull : *pulls) {
    for (int axis = 0; axis < 6; ++axis) {
      const double sigma = std::sqrt(std::max(covariance(axis, axis), 0.0));
      pull.pull_sigmas[axis] = undetermined[axis] || !(sigma > 0) ? 0 : pull.pull[axis] / sigma;
      if (undetermined[axis]) pull.significance[axis] = 0;
    }
  }
}

std::vector<std::string> DescribeTermDisagreements(const std::vector<TermPull>& pulls) {
  std::vector<std::string> sentences;
  for (int axis = 0; axis < 6; ++axis) {
    const TermPull* most = nullptr;
    const TermPull* least = nullptr;
    for (const TermPull& pull : pulls) {
      if (!most || pull.significance[axis] > most->significance[axis]) most = &pull;
      if (!least || pull.significance[axis] < least->significance[axis]) least = &pull;
    }
    if (!most || most->significance[axis] <= kTermDisagreementSignificance ||
        least->significance[axis] >= -kTermDisagreementSignificance) {
      continue;
    }
    std::ostringstream sentence;
    sentence << std::fixed << std::setprecision(1) << "the " << most->term << " and " << least->term
             << " terms pull cam_from_lidar's " << kAxisNames[axis]
             << " apart, each beyond its own noise (t = " << std::showpos
             << most->significance[axis] << " and " << least->significance[axis] << "; pulls of "
             << most->pull_sigmas[axis] << " and " << least->pull_sigmas[axis] << std::noshowpos
             << " sigma): the sensors' data disagree, a sign of a sensor model error (the LiDAR's "
                "beam angles, the cameras' intrinsics, a clock offset); the estimate is a "
                "compromise between them";
    sentences.push_back(sentence.str());
  }
  return sentences;
}

}  // namespace colmap_lidar
