#include "lidar/model_evaluation.h"

#include "lidar/kd_tree.h"
#include "lidar/point_to_plane_icp.h"
#include "lidar/util/check_option.h"
#include "lidar/util/statistics.h"
#include "lidar/voxel_accumulator.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_set>

namespace colmap_lidar {

double DistanceToSampledSurface(const PointCloud& truth,
                                const KdTree3& tree,
                                double spacing,
                                const Eigen::Vector3d& point) {
  std::vector<size_t> indices;
  std::vector<double> squared;
  tree.KNearest(point, 8, &indices, &squared);
  if (indices.empty()) return 1e9;
  const double nearest = std::sqrt(squared[0]);
  double best = nearest;
  for (size_t k = 0; k < indices.size(); ++k) {
    const Eigen::Vector3d offset = point - truth.points[indices[k]];
    const double normal_distance = std::abs(truth.normals[indices[k]].dot(offset));
    const double tangential =
        std::sqrt(std::max(0.0, squared[k] - normal_distance * normal_distance));
    // Within the footprint of this sample, the plane is the surface.
    if (tangential <= spacing) best = std::min(best, normal_distance);
  }
  return best;
}

namespace {

double Percentile(std::vector<double> values, double q) {
  return values.empty() ? 0 : Quantile(std::move(values), q);
}

// The sampling spacing of the truth: median nearest-neighbour distance over a subset.
double TruthSpacing(const PointCloud& truth, const KdTree3& truth_tree) {
  std::vector<double> spacings;
  for (size_t i = 0; i < truth.Size(); i += std::max<size_t>(1, truth.Size() / 2000)) {
    std::vector<size_t> indices;
    std::vector<double> squared;
    truth_tree.KNearest(truth.points[i], 2, &indices, &squared);
    if (squared.size() == 2) spacings.push_back(std::sqrt(squared[1]));
  }
  return std::max(1e-6, Percentile(spacings, 0.5));
}

// The voxels (side: crop distance + truth spacing) holding a truth sample, dilated by one voxel. A
// point outside them is farther than the crop distance from every sample and from the sampled surface
// (DistanceToSampledSurface >= nearest distance - spacing), so it needs no k-d tree search: most of a
// street's or a site's dense points are far from the structure.
class NearTruthVoxels {
 public:
  NearTruthVoxels(const PointCloud& truth, double crop_distance, double spacing)
      : voxel_size_(crop_distance + spacing) {
    std::unordered_set<uint64_t> occupied;
    for (const Eigen::Vector3d& point : truth.points) occupied.insert(VoxelKey(point, voxel_size_));
    for (const uint64_t key : occupied) {
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            keys_.insert(NeighbourVoxelKey(key, Eigen::Vector3i(dx, dy, dz)));
          }
        }
      }
    }
  }

  bool MayBeNear(const Eigen::Vector3d& point) const {
    return keys_.count(VoxelKey(point, voxel_size_)) > 0;
  }

 private:
  double voxel_size_;
  std::unordered_set<uint64_t> keys_;
};

// The model points within the crop distance of the structure.
PointCloud PointsNearTruth(const PointCloud& model,
                           const KdTree3& truth_tree,
                           const NearTruthVoxels& near_truth,
                           double crop_distance_m) {
  std::vector<char> near(model.Size());
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < static_cast<int64_t>(model.Size()); ++i) {
    if (!near_truth.MayBeNear(model.points[i])) continue;
    size_t index;
    double squared;
    truth_tree.Nearest(model.points[i], &index, &squared);
    near[i] = squared <= crop_distance_m * crop_distance_m;
  }
  PointCloud cropped;
  for (size_t i = 0; i < model.Size(); ++i) {
    if (near[i]) cropped.points.push_back(model.points[i]);
  }
  return cropped;
}

// Rigid point-to-plane ICP of the model points near the structure (`cropped`).
void AlignByIcp(const PointCloud& cropped,
                const PointCloud& truth,
                const KdTree3& truth_tree,
                double spacing,
                const ModelEvaluationOptions& options,
                ModelEvaluation* result) {
  if (cropped.Size() < 6) return;
  IcpOptions icp;
  icp.max_iterations = std::max(1, options.icp_max_iterations);
  icp.max_correspondence_distance = options.crop_distance_m;
  icp.min_correspondence_distance = std::min(options.crop_distance_m, 4 * spacing);
  icp.max_source_points = 100000;
  const IcpResult aligned =
      PointToPlaneIcp(cropped, truth, truth_tree, Eigen::Isometry3d::Identity(), icp);
  result->truth_from_model = aligned.target_from_source;
  result->icp_converged = aligned.converged;
  result->icp_iterations = aligned.iterations;
}

void SummariseDistances(ModelEvaluation* result) {
  const std::vector<double>& distances = result->distances;
  double sum = 0, sum_squared = 0;
  for (double d : distances) {
    sum += d;
    sum_squared += d * d;
  }
  result->mean = sum / distances.size();
  result->rmse = std::sqrt(sum_squared / distances.size());
  result->median = Percentile(distances, 0.5);
  result->p90 = Percentile(distances, 0.9);
  result->p95 = Percentile(distances, 0.95);
  result->p99 = Percentile(distances, 0.99);
  result->max = *std::max_element(distances.begin(), distances.end());
}

// Precision (model to truth) and completeness (truth to model, from each truth sample to the nearest
// evaluated model point, queried once) at each threshold.
void ScoreThresholds(const PointCloud& truth,
                     const std::vector<Eigen::Vector3d>& evaluated_points,
                     const std::vector<double>& thresholds_m,
                     ModelEvaluation* result) {
  const KdTree3 model_tree(evaluated_points);
  std::vector<double> truth_to_model(truth.Size());
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < static_cast<int64_t>(truth.Size()); ++i) {
    size_t index;
    double squared;
    model_tree.Nearest(truth.points[i], &index, &squared);
    truth_to_model[i] = std::sqrt(squared);
  }
  for (double threshold : thresholds_m) {
    ModelEvaluation::AtThreshold at;
    at.threshold = threshold;
    size_t precise = 0, complete = 0;
    for (double d : result->distances) precise += d <= threshold;
    for (double d : truth_to_model) complete += d <= threshold;
    at.precision = static_cast<double>(precise) / result->distances.size();
    at.completeness = static_cast<double>(complete) / truth.Size();
    at.f_score = at.precision + at.completeness > 0
                     ? 2 * at.precision * at.completeness / (at.precision + at.completeness)
                     : 0;
    result->at_thresholds.push_back(at);
  }
}

}  // namespace

bool ModelEvaluationOptions::Check() const {
  LIDAR_CHECK_OPTION_GE(icp_max_iterations, 0);
  LIDAR_CHECK_OPTION_GT(crop_distance_m, 0);
  for (const double threshold : thresholds_m) LIDAR_CHECK_OPTION_GT(threshold, 0);
  return true;
}

ModelEvaluation EvaluateModel(const PointCloud& model,
                              const PointCloud& truth,
                              const ModelEvaluationOptions& options) {
  ThrowUnlessValid(options, "ModelEvaluationOptions");
  if (model.Empty()) throw std::invalid_argument("The model cloud is empty");
  if (truth.Empty() || !truth.HasNormals()) {
    throw std::invalid_argument("The ground-truth surface needs points with normals");
  }
  ModelEvaluation result;
  result.num_model_points = model.Size();
  result.num_truth_points = truth.Size();
  const KdTree3 truth_tree(truth.points);
  const double spacing = TruthSpacing(truth, truth_tree);
  const NearTruthVoxels near_truth(truth, options.crop_distance_m, spacing);
  if (options.align_icp) {
    AlignByIcp(PointsNearTruth(model, truth_tree, near_truth, options.crop_distance_m),
               truth,
               truth_tree,
               spacing,
               options,
               &result);
  }
  // After alignment, evaluate all model points within the crop distance.
  std::vector<double> distances(model.Size());
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < static_cast<int64_t>(model.Size()); ++i) {
    const Eigen::Vector3d point = result.truth_from_model * model.points[i];
    distances[i] = near_truth.MayBeNear(point)
                       ? DistanceToSampledSurface(truth, truth_tree, spacing, point)
                       : std::numeric_limits<double>::infinity();
  }
  std::vector<Eigen::Vector3d> evaluated_points;
  for (size_t i = 0; i < model.Size(); ++i) {
    if (distances[i] <= options.crop_distance_m) {
      result.distances.push_back(distances[i]);
      result.evaluated_indices.push_back(i);
      evaluated_points.push_back(result.truth_from_model * model.points[i]);
    }
  }
  result.num_evaluated = result.distances.size();
  if (result.distances.empty()) return result;
  SummariseDistances(&result);
  ScoreThresholds(truth, evaluated_points, options.thresholds_m, &result);

  // Density on the structure: evaluated points per cm^2 of the true surface they cover. Each truth
  // sample stands for spacing^2 of surface; the covered part is the completeness at the largest threshold.
  const double covered_fraction =
      result.at_thresholds.empty() ? 1.0 : result.at_thresholds.back().completeness;
  const double covered_area_cm2 = covered_fraction * truth.Size() * spacing * spacing * 1e4;
  result.density_points_per_cm2 =
      covered_area_cm2 > 0 ? result.num_evaluated / covered_area_cm2 : 0;
  return result;
}

}  // namespace colmap_lidar
