#include "lidar/registration_quality.h"

#include "lidar/util/parallel_for_each.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {

double PlaneNoiseRms(const PointCloud& cloud, const KdTree3& tree, size_t max_points) {
  if (!cloud.HasNormals()) throw std::invalid_argument("PlaneNoiseRms: the cloud needs normals");
  if (tree.Size() != cloud.Size()) {
    throw std::invalid_argument("PlaneNoiseRms: the k-d tree is not built over the cloud");
  }
  const size_t stride = std::max<size_t>(1, cloud.Size() / std::max<size_t>(1, max_points));
  struct SquaredSum {
    double squared_sum = 0;
    size_t count = 0;
    void Add(const SquaredSum& other) {
      squared_sum += other.squared_sum;
      count += other.count;
    }
  };
  const long num = static_cast<long>(cloud.Size() / stride);
  const SquaredSum sum = ChunkedSum<SquaredSum>(num, [&](long k, SquaredSum* chunk) {
    const Eigen::Vector3d& p = cloud.points[k * stride];
    std::vector<size_t> indices;
    std::vector<double> squared_distances;
    tree.KNearest(p, 2, &indices, &squared_distances);
    if (indices.size() < 2) return;
    const size_t q = indices[0] == static_cast<size_t>(k * stride) ? indices[1] : indices[0];
    const Eigen::Vector3d& n = cloud.normals[q];
    if (n.squaredNorm() < 0.5) return;
    const double r = n.dot(p - cloud.points[q]);
    chunk->squared_sum += r * r;
    ++chunk->count;
  });
  return sum.count ? std::sqrt(sum.squared_sum / sum.count) : 0.0;
}

std::string ConstraintAnalysis::WeakestAxisName() const {
  static const char* kNames[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};
  int axis = 0;
  weakest_direction.cwiseAbs().maxCoeff(&axis);
  return kNames[axis];
}

ConstraintAnalysis AnalyseConstraints(const Eigen::Matrix<double, 6, 6>& hessian,
                                      double lever_arm_m) {
  if (!(lever_arm_m > 0)) throw std::invalid_argument("AnalyseConstraints: lever arm must be > 0");
  // x = S y with y = [omega * L, t]: H_y = S H S, S = diag(1/L, 1/L, 1/L, 1, 1, 1).
  Eigen::Matrix<double, 6, 1> scale;
  scale << Eigen::Vector3d::Constant(1 / lever_arm_m), Eigen::Vector3d::Ones();
  const Eigen::Matrix<double, 6, 6> scaled = scale.asDiagonal() * hessian * scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(scaled);
  ConstraintAnalysis analysis;
  const double largest = eigen.eigenvalues()(5);
  if (eigen.info() != Eigen::Success || !(largest > 0)) return analysis;
  analysis.weakest_ratio = std::max(0.0, eigen.eigenvalues()(0)) / largest;
  analysis.weakest_direction = eigen.eigenvectors().col(0);
  return analysis;
}

}  // namespace colmap_lidar
