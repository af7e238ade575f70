#include "lidar/lidar_surface.h"

#include "lidar/kd_tree.h"
#include "lidar/preprocessing.h"
#include "lidar/util/check_option.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace colmap_lidar {
namespace {

struct Pca {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();  // ascending
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();      // smallest eigenvector
};

// PCA of the indexed samples, at most `max_count` of them taken evenly.
Pca NeighbourhoodPca(const std::vector<Eigen::Vector3d>& samples,
                     const std::vector<size_t>& indices,
                     int max_count) {
  const size_t stride = (indices.size() + max_count - 1) / max_count;
  Pca pca;
  size_t count = 0;
  for (size_t k = 0; k < indices.size(); k += stride, ++count) {
    pca.mean += samples[indices[k]];
  }
  pca.mean /= double(count);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < indices.size(); k += stride) {
    const Eigen::Vector3d d = samples[indices[k]] - pca.mean;
    covariance += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  pca.eigenvalues = solver.eigenvalues();
  pca.normal = solver.eigenvectors().col(0);
  return pca;
}

double Curvature(const Pca& pca) {
  const double sum = pca.eigenvalues.sum();
  return sum > 0 ? std::max(0.0, pca.eigenvalues(0)) / sum : 0.0;
}

// A sparse sample's neighbourhood: 1.5x the distance to its min_neighbors-th nearest sample
// (`kth_distance`), doubled while it is a line (one scan line: it must span the next one), up to
// max_radius_m: its radius, its PCA and whether that is a plane.
struct GrownPca {
  double radius = 0;
  Pca pca;
  bool valid = false;
};

GrownPca GrownNeighbourhood(const std::vector<Eigen::Vector3d>& samples,
                            const KdTree3& tree,
                            size_t i,
                            double kth_distance,
                            const LidarSurfaceOptions& options,
                            std::vector<size_t>* indices) {
  GrownPca grown;
  double& r = grown.radius;
  r = std::min(options.max_radius_m, std::max(options.radius_m, 1.5 * kth_distance));
  for (;;) {
    tree.RadiusSearch(samples[i], r, indices);
    if (static_cast<int>(indices->size()) >= options.min_neighbors) {
      grown.pca = NeighbourhoodPca(samples, *indices, options.max_neighbors);
      grown.valid = grown.pca.eigenvalues(1) >= options.min_planarity * grown.pca.eigenvalues(2);
    }
    if (grown.valid || r >= options.max_radius_m) return grown;
    r = std::min(options.max_radius_m, 2 * r);
  }
}

// Each sample's mean distance to its 4 nearest other samples (a count in the radius would double
// the spacing at a border, where half the disc is empty, and fatten the border's splats) and to its
// min_neighbors-th nearest.
void NeighbourDistances(const std::vector<Eigen::Vector3d>& samples,
                        const KdTree3& tree,
                        const LidarSurfaceOptions& options,
                        std::vector<float>* spacing,
                        std::vector<double>* kth_distance) {
  spacing->assign(samples.size(), float(options.sample_spacing_m));
  kth_distance->assign(samples.size(), 0.0);
  const size_t num_nearest =
      options.grow_sparse_neighbourhoods ? std::max(5, options.min_neighbors + 1) : 5;
#pragma omp parallel
  {
    std::vector<size_t> nearest;
    std::vector<double> squared;
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < samples.size(); ++i) {
      // The min_neighbors-th nearest only when a sparse sample may grow its neighbourhood.
      tree.KNearest(samples[i], num_nearest, &nearest, &squared);
      const size_t four = std::min<size_t>(5, nearest.size());
      double sum = 0;
      for (size_t k = 1; k < four; ++k) sum += std::sqrt(squared[k]);
      if (four > 1) (*spacing)[i] = float(sum / (four - 1));
      (*kth_distance)[i] = std::sqrt(squared.back());
    }
  }
}

// Each sample's PCA radius and its neighbourhood plane (`valid` false with fewer than min_neighbors
// samples in the radius, or a line): radius_m, or with grow_sparse_neighbourhoods a sample with too
// few grows its own (GrownNeighbourhood).
struct OwnPcas {
  std::vector<Pca> pcas;
  std::vector<char> valid;
  std::vector<double> radius;
};

OwnPcas OwnNeighbourhoods(const std::vector<Eigen::Vector3d>& samples,
                          const KdTree3& tree,
                          const LidarSurfaceOptions& options,
                          const std::vector<double>& kth_distance) {
  OwnPcas own;
  own.pcas.assign(samples.size(), Pca());
  own.valid.assign(samples.size(), 0);
  own.radius.assign(samples.size(), options.radius_m);
#pragma omp parallel
  {
    std::vector<size_t> indices;
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < samples.size(); ++i) {
      tree.RadiusSearch(samples[i], options.radius_m, &indices);
      if (static_cast<int>(indices.size()) >= options.min_neighbors) {
        own.pcas[i] = NeighbourhoodPca(samples, indices, options.max_neighbors);
        own.valid[i] = 1;
      } else if (options.grow_sparse_neighbourhoods) {
        const GrownPca grown =
            GrownNeighbourhood(samples, tree, i, kth_distance[i], options, &indices);
        own.radius[i] = grown.radius;
        own.pcas[i] = grown.pca;
        own.valid[i] = grown.valid;
      }
    }
  }
  return own;
}

// The thinned samples with their search tree and own neighbourhoods' PCA (valid: enough
// neighbours).
struct SampleNeighbourhoods {
  const std::vector<Eigen::Vector3d>& samples;
  const KdTree3& tree;
  const std::vector<Pca>& own;
  const std::vector<char>& valid;
};

// Neighbourhood shifting: besides sample i's own neighbourhood, those centred on samples half a
// radius away; the flattest. Near a corner that is a neighbourhood on the sample's own face, so the
// corner stays sharp instead of being rounded off by a radius. `indices`: scratch.
const Pca* FlattestShiftedNeighbourhood(const SampleNeighbourhoods& n,
                                        double radius,
                                        size_t i,
                                        const LidarSurfaceOptions& options,
                                        std::vector<size_t>* indices) {
  const std::vector<Eigen::Vector3d>& samples = n.samples;
  n.tree.RadiusSearch(samples[i], radius, indices);
  std::vector<size_t> candidates;
  for (size_t j : *indices) {
    const double d = (samples[j] - samples[i]).norm();
    if (d > 0.35 * radius && d < 0.65 * radius) candidates.push_back(j);
  }
  const size_t stride = std::max<size_t>(1, candidates.size() / options.num_shifted_neighbourhoods);
  const Pca* pca = &n.own[i];
  double best = Curvature(*pca);
  for (size_t k = 0; k < candidates.size(); k += stride) {
    if (!n.valid[candidates[k]]) continue;
    const double c = Curvature(n.own[candidates[k]]);
    if (c < best) best = c, pca = &n.own[candidates[k]];
  }
  return pca;
}

}  // namespace

bool LidarSurfaceOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(sample_spacing_m, 0);
  LIDAR_CHECK_OPTION_GT(radius_m, sample_spacing_m);
  LIDAR_CHECK_OPTION_GE(max_radius_m, radius_m);
  LIDAR_CHECK_OPTION_GE(min_planarity, 0);
  LIDAR_CHECK_OPTION_LT(min_planarity, 1);
  LIDAR_CHECK_OPTION_GT(curvature_radius_m, 0);
  LIDAR_CHECK_OPTION_GE(min_neighbors, 3);
  LIDAR_CHECK_OPTION_GE(max_neighbors, min_neighbors);
  return true;
}

LidarSurface BuildLidarSurface(const std::vector<Eigen::Vector3d>& points_in_cam,
                               const LidarSurfaceOptions& options) {
  ThrowUnlessValid(options, "LidarSurfaceOptions");
  LidarSurface surface;
  if (points_in_cam.empty()) return surface;
  PointCloud raw;
  raw.points = points_in_cam;
  const PointCloud thinned = VoxelDownsample(raw, options.sample_spacing_m);
  const std::vector<Eigen::Vector3d>& samples = thinned.points;
  const KdTree3 tree(samples);
  // Every neighbourhood once: a shifted neighbourhood centred on sample j is sample j's own.
  std::vector<float> spacing;
  std::vector<double> kth_distance;
  NeighbourDistances(samples, tree, options, &spacing, &kth_distance);
  const OwnPcas own_pcas = OwnNeighbourhoods(samples, tree, options, kth_distance);
  const std::vector<Pca>& own = own_pcas.pcas;
  const std::vector<char>& valid = own_pcas.valid;
  const std::vector<double>& radius = own_pcas.radius;
  const SampleNeighbourhoods neighbourhoods{samples, tree, own, valid};

  std::vector<Eigen::Vector3d> points(samples.size());
  std::vector<Eigen::Vector3d> normals(samples.size());
  std::vector<float> curvature(samples.size(), -1.f);  // -1: dropped
#pragma omp parallel
  {
    std::vector<size_t> indices;
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < samples.size(); ++i) {
      if (!valid[i]) continue;
      const Pca* pca =
          options.num_shifted_neighbourhoods > 0
              ? FlattestShiftedNeighbourhood(neighbourhoods, radius[i], i, options, &indices)
              : &own[i];
      Eigen::Vector3d normal = pca->normal;
      if (normal.dot(samples[i]) > 0) normal = -normal;  // face the camera
      points[i] = samples[i] - normal * normal.dot(samples[i] - pca->mean);
      normals[i] = normal;
      double c = Curvature(*pca);
      if (options.curvature_radius_m != options.radius_m) {
        tree.RadiusSearch(
            samples[i], options.curvature_radius_m * radius[i] / options.radius_m, &indices);
        c = Curvature(NeighbourhoodPca(samples, indices, options.max_neighbors));
      }
      curvature[i] = float(c);
    }
  }
  for (size_t i = 0; i < samples.size(); ++i) {
    if (curvature[i] < 0) continue;
    surface.points.push_back(points[i]);
    surface.normals.push_back(normals[i]);
    surface.curvature.push_back(curvature[i]);
    surface.spacing.push_back(spacing[i]);
  }
  return surface;
}

}  // namespace colmap_lidar
