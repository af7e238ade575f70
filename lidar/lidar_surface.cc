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

// Each sample's own neighbourhood plane (`valid` false with fewer than min_neighbors samples in the
// radius) and the mean distance to its 4 nearest other samples (a count in the radius would double
// the spacing at a border, where half the disc is empty, and fatten the border's splats).
void OwnNeighbourhoods(const std::vector<Eigen::Vector3d>& samples,
                       const KdTree3& tree,
                       const LidarSurfaceOptions& options,
                       std::vector<Pca>* pcas,
                       std::vector<char>* valid,
                       std::vector<float>* spacing) {
  pcas->assign(samples.size(), Pca());
  valid->assign(samples.size(), 0);
  spacing->assign(samples.size(), 0.f);
#pragma omp parallel
  {
    std::vector<size_t> indices, nearest;
    std::vector<double> squared;
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < samples.size(); ++i) {
      tree.RadiusSearch(samples[i], options.radius_m, &indices);
      if (static_cast<int>(indices.size()) < options.min_neighbors) continue;
      (*pcas)[i] = NeighbourhoodPca(samples, indices, options.max_neighbors);
      (*valid)[i] = 1;
      tree.KNearest(samples[i], 5, &nearest, &squared);
      double sum = 0;
      for (size_t k = 1; k < nearest.size(); ++k) sum += std::sqrt(squared[k]);
      (*spacing)[i] =
          float(nearest.size() > 1 ? sum / (nearest.size() - 1) : options.sample_spacing_m);
    }
  }
}

}  // namespace

bool LidarSurfaceOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(sample_spacing_m, 0);
  LIDAR_CHECK_OPTION_GT(radius_m, sample_spacing_m);
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
  OwnNeighbourhoods(samples, tree, options, &own, &valid, &spacing);

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
        tree.RadiusSearch(samples[i], options.radius_m, &indices);
        candidates.clear();
        for (size_t j : indices) {
          const double d = (samples[j] - samples[i]).norm();
          if (d > 0.35 * options.radius_m && d < 0.65 * options.radius_m) {
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
        tree.RadiusSearch(samples[i], options.curvature_radius_m, &indices);
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
