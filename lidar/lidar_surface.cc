#include "lidar/lidar_surface.h"

#include "lidar/check_option.h"
#include "lidar/kd_tree.h"
#include "lidar/preprocessing.h"

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
// max_radius_m. Returns the radius; `valid` says whether a plane was found.
double GrownNeighbourhood(const std::vector<Eigen::Vector3d>& samples,
                          const KdTree3& tree,
                          size_t i,
                          double kth_distance,
                          const LidarSurfaceOptions& options,
                          std::vector<size_t>* indices,
                          Pca* pca,
                          char* valid) {
  double r = std::min(options.max_radius_m, std::max(options.radius_m, 1.5 * kth_distance));
  for (;;) {
    tree.RadiusSearch(samples[i], r, indices);
    if (static_cast<int>(indices->size()) >= options.min_neighbors) {
      *pca = NeighbourhoodPca(samples, *indices, options.max_neighbors);
      *valid = pca->eigenvalues(1) >= options.min_planarity * pca->eigenvalues(2);
    }
    if (*valid || r >= options.max_radius_m) return r;
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
void OwnNeighbourhoods(const std::vector<Eigen::Vector3d>& samples,
                       const KdTree3& tree,
                       const LidarSurfaceOptions& options,
                       const std::vector<double>& kth_distance,
                       std::vector<Pca>* pcas,
                       std::vector<char>* valid,
                       std::vector<double>* radius) {
  pcas->assign(samples.size(), Pca());
  valid->assign(samples.size(), 0);
  radius->assign(samples.size(), options.radius_m);
#pragma omp parallel
  {
    std::vector<size_t> indices;
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < samples.size(); ++i) {
      tree.RadiusSearch(samples[i], options.radius_m, &indices);
      if (static_cast<int>(indices.size()) >= options.min_neighbors) {
        (*pcas)[i] = NeighbourhoodPca(samples, indices, options.max_neighbors);
        (*valid)[i] = 1;
      } else if (options.grow_sparse_neighbourhoods) {
        (*radius)[i] = GrownNeighbourhood(
            samples, tree, i, kth_distance[i], options, &indices, &(*pcas)[i], &(*valid)[i]);
      }
    }
  }
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
  std::vector<Pca> own;
  std::vector<char> valid;
  std::vector<float> spacing;
  std::vector<double> kth_distance, radius;
  NeighbourDistances(samples, tree, options, &spacing, &kth_distance);
  OwnNeighbourhoods(samples, tree, options, kth_distance, &own, &valid, &radius);

  std::vector<Eigen::Vector3d> points(samples.size());
  std::vector<Eigen::Vector3d> normals(samples.size());
  std::vector<float> curvature(samples.size(), -1.f);  // -1: dropped
#pragma omp parallel
  {
    std::vector<size_t> indices, candidates;
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < samples.size(); ++i) {
      if (!valid[i]) continue;
      const Pca* pca = &own[i];
      if (options.num_shifted_neighbourhoods > 0) {
        // Neighbourhood shifting: also take the neighbourhoods centred on samples half a radius
        // away and keep the flattest. Near a corner that is a neighbourhood on the sample's own face,
        // so the corner stays sharp instead of being rounded off by a radius.
        tree.RadiusSearch(samples[i], radius[i], &indices);
        candidates.clear();
        for (size_t j : indices) {
          const double d = (samples[j] - samples[i]).norm();
          if (d > 0.35 * radius[i] && d < 0.65 * radius[i]) {
            candidates.push_back(j);
          }
        }
        const size_t stride =
            std::max<size_t>(1, candidates.size() / options.num_shifted_neighbourhoods);
        double best = Curvature(*pca);
        for (size_t k = 0; k < candidates.size(); k += stride) {
          if (!valid[candidates[k]]) continue;
          const double c = Curvature(own[candidates[k]]);
          if (c < best) best = c, pca = &own[candidates[k]];
        }
      }
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
