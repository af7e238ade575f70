#include "lidar/bsc_descriptor.h"

#include "lidar/util/check_option.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <random>
#include <stdexcept>

namespace colmap_lidar {
namespace {

struct CellPair {
  int a, b;
};

std::vector<CellPair> MakeCellPairs(int num_cells, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> cell(0, num_cells - 1);
  std::vector<CellPair> pairs;
  while (static_cast<int>(pairs.size()) < num_cells) {
    const int a = cell(rng), b = cell(rng);
    if (a != b) pairs.push_back({a, b});
  }
  return pairs;
}

void SetBit(int bit, BscDescriptor* descriptor) {
  (*descriptor)[bit / 64] |= uint64_t{1} << (bit % 64);
}

// Sets `count` comparison bits starting at `first_bit` from the cell values.
void ComparisonBits(const std::vector<double>& values,
                    const std::vector<CellPair>& pairs,
                    int first_bit,
                    BscDescriptor* descriptor) {
  std::vector<double> differences(pairs.size());
  double mean = 0;
  for (size_t k = 0; k < pairs.size(); ++k) {
    differences[k] = values[pairs[k].a] - values[pairs[k].b];
    mean += differences[k];
  }
  mean /= pairs.size();
  double variance = 0;
  for (double d : differences) variance += (d - mean) * (d - mean);
  const double std_dev = std::sqrt(variance / pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (std::abs(differences[k] - mean) > std_dev)
      SetBit(first_bit + static_cast<int>(k), descriptor);
  }
}

BscDescriptor Describe(const std::vector<Eigen::Vector3d>& local,  // neighbours in the LRF, / R
                       const std::vector<CellPair>& pairs,
                       const BscOptions& options) {
  const int n = options.grid_size;
  const int num_cells = n * n;
  BscDescriptor descriptor(options.NumWords(), 0);
  constexpr int kPlaneAxes[3][3] = {{0, 1, 2}, {0, 2, 1}, {1, 2, 0}};  // (u, v, depth): XY, XZ, YZ
  std::vector<double> density(num_cells), depth_sum(num_cells), mean_depth(num_cells);
  for (int plane = 0; plane < 3; ++plane) {
    std::fill(density.begin(), density.end(), 0.0);
    std::fill(depth_sum.begin(), depth_sum.end(), 0.0);
    double total = 0;
    for (const Eigen::Vector3d& l : local) {
      // Continuous cell coordinates: cell centres at integers 0..n-1 over [-1, 1].
      const double u = (l[kPlaneAxes[plane][0]] + 1) * n / 2 - 0.5;
      const double v = (l[kPlaneAxes[plane][1]] + 1) * n / 2 - 0.5;
      const double depth = l[kPlaneAxes[plane][2]];
      const int cu = static_cast<int>(std::lround(u)), cv = static_cast<int>(std::lround(v));
      for (int du = -1; du <= 1; ++du) {
        for (int dv = -1; dv <= 1; ++dv) {
          const int iu = cu + du, iv = cv + dv;
          if (iu < 0 || iv < 0 || iu >= n || iv >= n) continue;
          // Gaussian with sigma = half a cell.
          const double w = std::exp(-2.0 * ((iu - u) * (iu - u) + (iv - v) * (iv - v)));
          density[iv * n + iu] += w;
          depth_sum[iv * n + iu] += w * depth;
          total += w;
        }
      }
    }
    if (total <= 0) continue;
    double mean_density = 0;
    for (int c = 0; c < num_cells; ++c) {
      mean_depth[c] = density[c] > 0 ? depth_sum[c] / density[c] : 0;
      density[c] /= total;
      mean_density += density[c];
    }
    mean_density /= num_cells;
    const int first = plane * 3 * num_cells;
    for (int c = 0; c < num_cells; ++c) {
      if (density[c] > options.occupancy_ratio * mean_density) SetBit(first + c, &descriptor);
    }
    ComparisonBits(density, pairs, first + num_cells, &descriptor);
    ComparisonBits(mean_depth, pairs, first + 2 * num_cells, &descriptor);
  }
  return descriptor;
}

// The local reference frame of a keypoint at `center` (Dong et al. 2017): z the normal of the
// covariance of `neighbors` weighted by R - d, towards the viewpoint (into *z); the x axes to
// describe with: the axis of largest spread, signed by the majority of the points, its mirror where
// the sign is ambiguous, and +-y where the two largest spreads are alike. Empty: no frame.
std::vector<Eigen::Vector3d> LrfCandidates(const PointCloud& cloud,
                                           const std::vector<size_t>& neighbors,
                                           const Eigen::Vector3d& center,
                                           const Eigen::Vector3d& viewpoint,
                                           const BscOptions& options,
                                           Eigen::Vector3d* z) {
  const double R = options.support_radius;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double weight_sum = 0;
  for (size_t j : neighbors) {
    const Eigen::Vector3d d = cloud.points[j] - center;
    const double w = R - d.norm();
    covariance += w * d * d.transpose();
    weight_sum += w;
  }
  if (weight_sum <= 0) return {};
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance / weight_sum);
  *z = solver.eigenvectors().col(0);
  Eigen::Vector3d x = solver.eigenvectors().col(2);
  if (z->dot(viewpoint - center) < 0) *z = -*z;
  double majority = 0, magnitude = 0;
  for (size_t j : neighbors) {
    const Eigen::Vector3d d = cloud.points[j] - center;
    const double projection = (R - d.norm()) * x.dot(d);
    majority += projection;
    magnitude += std::abs(projection);
  }
  if (majority < 0) x = -x;
  std::vector<Eigen::Vector3d> x_axes = {x};
  if (std::abs(majority) < options.sign_ambiguity * magnitude) x_axes.push_back(-x);
  const Eigen::Vector3d ascending = solver.eigenvalues().cwiseMax(0);
  if (ascending(2) > 0 && ascending(1) / ascending(2) > options.ambiguity_ratio) {
    const Eigen::Vector3d y = z->cross(x);
    x_axes.push_back(y);
    x_axes.push_back(-y);
  }
  return x_axes;
}

}  // namespace

bool BscOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(support_radius, 0);
  LIDAR_CHECK_OPTION_GE(grid_size, 2);
  LIDAR_CHECK_OPTION_GE(occupancy_ratio, 0);
  LIDAR_CHECK_OPTION_GE(min_neighbors, 3);
  return true;
}

std::vector<BscFeature> ComputeBscFeatures(const PointCloud& cloud,
                                           const KdTree3& tree,
                                           const std::vector<size_t>& keypoints,
                                           const Eigen::Vector3d& viewpoint,
                                           const BscOptions& options) {
  ThrowUnlessValid(options, "BscOptions");
  const double R = options.support_radius;
  const std::vector<CellPair> pairs =
      MakeCellPairs(options.grid_size * options.grid_size, options.pair_seed);
  std::vector<BscFeature> features(keypoints.size());
  std::vector<char> valid(keypoints.size(), 0);
#pragma omp parallel
  {
    std::vector<size_t> neighbors;
    std::vector<Eigen::Vector3d> local;
    Eigen::Vector3d z;
#pragma omp for schedule(dynamic, 16)
    for (size_t k = 0; k < keypoints.size(); ++k) {
      const Eigen::Vector3d center = cloud.points.at(keypoints[k]);
      tree.RadiusSearch(center, R, &neighbors);
      if (static_cast<int>(neighbors.size()) < options.min_neighbors) continue;
      const std::vector<Eigen::Vector3d> x_axes =
          LrfCandidates(cloud, neighbors, center, viewpoint, options, &z);
      if (x_axes.empty()) continue;
      BscFeature& feature = features[k];
      feature.point_index = keypoints[k];
      feature.position = center;
      for (size_t v = 0; v < x_axes.size(); ++v) {
        Eigen::Matrix3d cloud_from_lrf;
        cloud_from_lrf << x_axes[v], z.cross(x_axes[v]), z;
        if (v == 0) feature.cloud_from_lrf = cloud_from_lrf;
        local.clear();
        for (size_t j : neighbors) {
          local.push_back((cloud_from_lrf.transpose() * (cloud.points[j] - center) / R)
                              .cwiseMax(-1.0)
                              .cwiseMin(1.0));
        }
        feature.variants.push_back(Describe(local, pairs, options));
      }
      valid[k] = 1;
    }
  }
  std::vector<BscFeature> result;
  for (size_t k = 0; k < features.size(); ++k) {
    if (valid[k]) result.push_back(std::move(features[k]));
  }
  return result;
}

int HammingDistance(const BscDescriptor& a, const BscDescriptor& b) {
  int distance = 0;
  for (size_t w = 0; w < a.size(); ++w) distance += __builtin_popcountll(a[w] ^ b[w]);
  return distance;
}

int BscDistance(const BscFeature& a, const BscFeature& b) {
  int best = 1 << 30;
  for (const BscDescriptor& da : a.variants) {
    for (const BscDescriptor& db : b.variants) best = std::min(best, HammingDistance(da, db));
  }
  return best;
}

}  // namespace colmap_lidar
