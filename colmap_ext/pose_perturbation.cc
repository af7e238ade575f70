#include "colmap_ext/pose_perturbation.h"

#include <cmath>
#include <random>

namespace colmap_lidar {

colmap::Rigid3d PerturbPose(const colmap::Rigid3d& truth,
                            double rotation_deg,
                            double translation_m,
                            uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  const Eigen::Vector3d shift = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  colmap::Rigid3d perturbed = truth;
  perturbed.rotation =
      (Eigen::Quaterniond(Eigen::AngleAxisd(rotation_deg * (M_PI / 180), axis)) * truth.rotation)
          .normalized();
  perturbed.translation += translation_m * shift;
  return perturbed;
}

}  // namespace colmap_lidar
