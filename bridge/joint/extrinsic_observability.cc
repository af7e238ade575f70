#include "bridge/joint/extrinsic_observability.h"

#include "bridge/joint/problem_columns.h"
#include "bridge/joint/subspace_manifold.h"
#include "colmap_ext/logging.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <ceres/cost_function.h>
#include <ceres/crs_matrix.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <map>
#include <optional>
#include <sstream>

namespace colmap_lidar {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
// Degrees of rotation per unit of the quaternion manifold's tangent.
constexpr double kTangentToRotationDeg = 2.0 * kRadToDeg;

std::string DescribeAxis(const Eigen::Vector3d& axis) {
  const Eigen::Vector3d a = axis.normalized();
  static const char* kNames[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    if (std::abs(a[i]) > 0.9) return std::string("the camera ") + kNames[i] + " axis";
  }
  std::ostringstream out;
  out << std::fixed << std::setprecision(2) << "the camera-frame direction (" << a.x() << ", "
      << a.y() << ", " << a.z() << ")";
  return out.str();
}

std::string Advice(const MotionAnalysis& motion) {
  if (motion.num_rotating_pairs == 0) {
    return "the stations do not rotate relative to each other; add stations "
           "rotated about two different axes";
  }
  if (!motion.unique && motion.num_stations >= 3) {
    return "all stations rotate about one axis (" + DescribeAxis(motion.common_axis_in_cam) +
           "); add stations tilted about a second axis";
  }
  if (motion.num_stations < 3) return "fewer than 3 stations; add stations";
  return "the observations do not constrain it; add overlapping stations";
}

}  // namespace

bool ObservabilityOptions::Check() const {
  CHECK_OPTION_GT(unobservable_translation_mm, 0);
  CHECK_OPTION_GT(unobservable_rotation_deg, 0);
  CHECK_OPTION_GE(min_rotation_deg, 0);
  CHECK_OPTION_GE(stereo_scale_sigma, 0);
  CHECK_OPTION_GE(disparity_bias_sigma_px, 0);
  CHECK_OPTION_GT(max_parallel_axes_deg, 0);
  return true;
}

namespace {

// The largest rotation about an axis perpendicular to the main axis of the rotations (the top
// eigenvector of sum r r^T over the rotation vectors r, degrees). The axes of small rotations
// scatter with the pose noise (a car's 2-3 deg turns: 8 deg apart), but their rotation about any
// second axis stays a fraction of a degree; two-axis motion turns by degrees about it.
double LargestRotationOffMainAxisDeg(const std::vector<Eigen::Vector3d>& rotation_vectors) {
  if (rotation_vectors.empty()) return 0;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& r : rotation_vectors) scatter += r * r.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const Eigen::Vector3d main_axis = solver.eigenvectors().col(2);
  double largest = 0;
  for (const Eigen::Vector3d& r : rotation_vectors) {
    largest = std::max(largest, (r - r.dot(main_axis) * main_axis).norm());
  }
  return largest;
}

// The principal direction of b's camera centre seen from camera a, over all registered pairs.
Eigen::Vector3d TravelDirectionInCam(const colmap::Reconstruction& reconstruction) {
  const std::vector<colmap::image_t>& ids = reconstruction.RegImageIds();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const colmap::image_t a : ids) {
    for (const colmap::image_t b : ids) {
      const Eigen::Vector3d b_in_a =
          reconstruction.Image(a).CamFromWorld() * reconstruction.Image(b).ProjectionCenter();
      if (a != b && b_in_a.norm() > 0)
        scatter += b_in_a.normalized() * b_in_a.normalized().transpose();
    }
  }
  if (scatter.isZero()) return Eigen::Vector3d::Zero();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2);
}

}  // namespace

double LargestAngleBetweenAxesDeg(const std::vector<Eigen::Vector3d>& unit_axes) {
  const auto line_angle_deg = [&](size_t a, size_t b) {
    const Eigen::Vector3d& first = unit_axes[std::min(a, b)];
    const Eigen::Vector3d& second = unit_axes[std::max(a, b)];
    return std::acos(std::min(1.0, std::abs(first.dot(second)))) * kRadToDeg;
  };
  if (unit_axes.size() < 2) return 0;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& axis : unit_axes) scatter += axis * axis.transpose();
  const Eigen::Vector3d main_axis =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2);
  // Axes by their angle from the main direction, farthest first.
  std::vector<std::pair<double, size_t>> from_main;
  for (size_t a = 0; a < unit_axes.size(); ++a) {
    const double cosine = std::min(1.0, std::abs(unit_axes[a].dot(main_axis)));
    from_main.emplace_back(std::acos(cosine) * kRadToDeg, a);
  }
  std::sort(from_main.begin(), from_main.end(), std::greater<>());
  // A pair's bound a + b is checked with a margin far above acos' rounding, so that the pair of
  // the largest angle is always compared.
  constexpr double kMarginDeg = 1e-6;
  double largest = 0;
  for (size_t i = 0; i + 1 < from_main.size(); ++i) {
    if (from_main[i].first + from_main[i + 1].first + kMarginDeg < largest) break;
    for (size_t j = i + 1; j < from_main.size(); ++j) {
      if (from_main[i].first + from_main[j].first + kMarginDeg < largest) break;
      largest = std::max(largest, line_angle_deg(from_main[i].second, from_main[j].second));
    }
  }
  return largest;
}

MotionAnalysis AnalyseMotion(const colmap::Reconstruction& reconstruction,
                             const ObservabilityOptions& options) {
  MotionAnalysis analysis;
  const std::vector<colmap::image_t>& ids = reconstruction.RegImageIds();
  analysis.num_stations = static_cast<int>(ids.size());
  std::vector<Eigen::Vector3d> axes, rotation_vectors;
  double largest_angle = 0;
  for (size_t a = 0; a < ids.size(); ++a) {
    for (size_t b = a + 1; b < ids.size(); ++b) {
      // The hand-eye motion A = cam_a_from_cam_b; its rotation axis as a vector.
      const Eigen::Quaterniond rotation =
          reconstruction.Image(ids[a]).CamFromWorld().rotation *
          reconstruction.Image(ids[b]).CamFromWorld().rotation.inverse();
      const Eigen::AngleAxisd angle_axis(rotation);
      if (angle_axis.angle() * kRadToDeg < options.min_rotation_deg) continue;
      axes.push_back(angle_axis.axis());
      rotation_vectors.push_back(angle_axis.angle() * kRadToDeg * angle_axis.axis());
      if (angle_axis.angle() > largest_angle) {
        largest_angle = angle_axis.angle();
        analysis.common_axis_in_cam = angle_axis.axis();
      }
    }
  }
  analysis.num_rotating_pairs = static_cast<int>(axes.size());
  analysis.travel_direction_in_cam = TravelDirectionInCam(reconstruction);
  analysis.max_axis_angle_deg = LargestAngleBetweenAxesDeg(axes);
  analysis.second_axis_rotation_deg = LargestRotationOffMainAxisDeg(rotation_vectors);
  analysis.unique = analysis.num_stations >= 3 &&
                    analysis.max_axis_angle_deg > options.max_parallel_axes_deg &&
                    analysis.second_axis_rotation_deg >= options.min_rotation_deg;
  std::ostringstream verdict;
  verdict << std::fixed << std::setprecision(1);
  if (analysis.num_stations < 3) {
    verdict << "only " << analysis.num_stations
            << " stations: the uniqueness condition of Zhen et al. 2019 needs at least 3";
  } else if (analysis.num_rotating_pairs == 0) {
    verdict << "the stations do not rotate relative to each other: T_e's "
               "rotation follows from the translations, its translation is "
               "unobservable";
  } else if (!analysis.unique) {
    verdict << "all relative rotations share one axis ("
            << DescribeAxis(analysis.common_axis_in_cam) << ", axes within "
            << analysis.max_axis_angle_deg << " deg, at most " << analysis.second_axis_rotation_deg
            << " deg about any other): T_e's translation along it is unobservable; add "
               "stations tilted about a second axis";
  } else {
    verdict << "relative rotation axes of " << analysis.num_rotating_pairs << " station pairs span "
            << analysis.max_axis_angle_deg
            << " deg: T_e is unique (Zhen et al. 2019's condition holds)";
  }
  analysis.verdict = verdict.str();
  return analysis;
}

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;

// Reported variances are capped here (sigma 10 m or 10^4 deg): a direction without information gets
// this instead of infinity, and the cap keeps the other directions' digits in a 6x6 eigensolve.
constexpr double kMaxVariance = 1e8;
// A direction whose nominal variance (whitened residuals, variance factor 1) from the data alone exceeds
// this (sigma 1 m or 1000 deg) is unobservable, whatever any prior says.
constexpr double kUnobservableVariance = 1e6;

// The variable parameter blocks in Jacobian column order, T_e last, and what T_e's tangent columns
// are in the reported 6-vector (rotation [deg] 0..2, translation [mm] 3..5): column j of the tangent
// is scale[j] reported units along the unit 6-vector directions.col(j). Held directions of T_e are no
// columns (a subspace manifold), so they get no variance.
struct ColumnLayout {
  std::vector<double*> blocks;
  int num_other = 0;
  Eigen::MatrixXd directions = Eigen::MatrixXd(6, 0);
  Eigen::VectorXd scale;
};

// Appends T_e block's free tangent columns: `basis` (3 x m) placed at rows `offset`..offset+2.
void AppendExtrinsicColumns(const Eigen::MatrixXd& basis,
                            int offset,
                            double unit,
                            ColumnLayout* layout) {
  const Eigen::Index m = layout->directions.cols();
  layout->directions.conservativeResize(6, m + basis.cols());
  layout->directions.rightCols(basis.cols()).setZero();
  layout->directions.block(offset, m, 3, basis.cols()) = basis;
  layout->scale.conservativeResize(m + basis.cols());
  layout->scale.tail(basis.cols()).setConstant(unit);
}

ColumnLayout MakeColumnLayout(const ExtrinsicUncertaintyInputs& inputs,
                              bool rotation_free,
                              bool translation_free) {
  ColumnLayout layout;
  ceres::Problem* problem = inputs.problem;
  for (double* block : ParameterBlocksInResidualOrder(*problem)) {
    if (block == inputs.cam_from_lidar_rotation || block == inputs.cam_from_lidar_translation ||
        problem->IsParameterBlockConstant(block)) {
      continue;
    }
    layout.blocks.push_back(block);
    layout.num_other += problem->ParameterBlockTangentSize(block);
  }
  if (rotation_free) {
    layout.blocks.push_back(inputs.cam_from_lidar_rotation);
    const Eigen::MatrixXd free = FreeDirectionsBasis(inputs.held_rotation);
    THROW_CHECK_EQ(problem->ParameterBlockTangentSize(inputs.cam_from_lidar_rotation), free.cols());
    AppendExtrinsicColumns(free, 0, kTangentToRotationDeg, &layout);
  }
  if (translation_free) {
    layout.blocks.push_back(inputs.cam_from_lidar_translation);
    const Eigen::MatrixXd free = FreeDirectionsBasis(inputs.held_translation);
    THROW_CHECK_EQ(problem->ParameterBlockTangentSize(inputs.cam_from_lidar_translation),
                   free.cols());
    AppendExtrinsicColumns(free, 3, 1000.0, &layout);
  }
  return layout;
}

// The Jacobian of the data residuals (cluster order) and of the regularisers (last rows).
constexpr int kRegularizerRow = -1;
constexpr int kMeasurementRow = -2;

struct JacobianRows {
  Eigen::SparseMatrix<double> jacobian;
  std::vector<double> residuals;
  // Per row: its cluster (kRegularizerRow, kMeasurementRow or >= 0) and d(residual)/d(the stereo
  // depth's consider parameters).
  std::vector<int> cluster;
  std::vector<Eigen::Vector4d> consider_derivative;
  int num_data_rows = 0;
};

JacobianRows EvaluateRows(
    ceres::Problem* problem,
    const ColumnLayout& layout,
    const std::vector<std::vector<ceres::ResidualBlockId>>& clusters,
    const std::vector<ceres::ResidualBlockId>& regularizers,
    const std::vector<ceres::ResidualBlockId>& measurements,
    const std::unordered_map<ceres::ResidualBlockId, Eigen::Vector4d>& depth_consider_derivative) {
  JacobianRows rows;
  std::vector<ceres::ResidualBlockId> residual_blocks;
  const auto add = [&](ceres::ResidualBlockId id, int cluster) {
    residual_blocks.push_back(id);
    const int num_residuals = problem->GetCostFunctionForResidualBlock(id)->num_residuals();
    rows.cluster.insert(rows.cluster.end(), num_residuals, cluster);
    const auto derivative = depth_consider_derivative.find(id);
    rows.consider_derivative.insert(rows.consider_derivative.end(),
                                    num_residuals,
                                    derivative == depth_consider_derivative.end()
                                        ? Eigen::Vector4d::Zero()
                                        : derivative->second);
  };
  for (size_t c = 0; c < clusters.size(); ++c) {
    for (const ceres::ResidualBlockId id : clusters[c]) add(id, static_cast<int>(c));
  }
  for (const ceres::ResidualBlockId id : measurements) add(id, kMeasurementRow);
  rows.num_data_rows = static_cast<int>(rows.cluster.size());
  for (const ceres::ResidualBlockId id : regularizers) add(id, kRegularizerRow);
  ceres::Problem::EvaluateOptions evaluate_options;
  evaluate_options.parameter_blocks = layout.blocks;
  evaluate_options.residual_blocks = residual_blocks;
  evaluate_options.num_threads = 2;
  double cost = 0;
  ceres::CRSMatrix crs;
  problem->Evaluate(evaluate_options, &cost, &rows.residuals, nullptr, &crs);
  THROW_CHECK_EQ(static_cast<size_t>(crs.num_rows), rows.cluster.size());
  THROW_CHECK_EQ(crs.num_cols, layout.num_other + static_cast<int>(layout.directions.cols()));
  rows.jacobian = SparseJacobian(crs);
  return rows;
}

// Information of T_e's free tangent with every other block marginalised (Schur complement); false if
// the other blocks are singular on their own.
bool MarginalInformation(const Eigen::SparseMatrix<double>& information,
                         int num_other,
                         Eigen::MatrixXd* marginal) {
  const int num_extrinsic = static_cast<int>(information.cols()) - num_other;
  Eigen::SparseMatrix<double> other = information.topLeftCorner(num_other, num_other);
  for (int i = 0; i < num_other; ++i) other.coeffRef(i, i) += 1e-12;
  const Eigen::MatrixXd coupling =
      Eigen::MatrixXd(information.bottomLeftCorner(num_extrinsic, num_other));
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(other);
  if (ldlt.info() != Eigen::Success) return false;
  *marginal = Eigen::MatrixXd(information.bottomRightCorner(num_extrinsic, num_extrinsic)) -
              coupling * ldlt.solve(Eigen::MatrixXd(coupling.transpose()));
  return true;
}

// A covariance of the scaled free directions (m x m, reported units) as the reported 6x6.
Matrix6 ToReported(const Eigen::MatrixXd& covariance, const ColumnLayout& layout) {
  return layout.directions * covariance * layout.directions.transpose();
}

// A tangent-space matrix in reported units along the free directions: covariances are multiplied by
// the scales on both sides, information matrices divided.
Eigen::MatrixXd ScaleTangent(const Eigen::MatrixXd& matrix, const ColumnLayout& layout, int power) {
  const Eigen::VectorXd scale = power > 0 ? layout.scale : layout.scale.cwiseInverse();
  return scale.asDiagonal() * matrix * scale.asDiagonal();
}

// The pseudo-inverse of an information matrix (whitened residuals) times the variance factor. A
// direction whose nominal variance 1/lambda exceeds kUnobservableVariance has no information from the
// data and gets the cap, whatever the factor (exact data has a factor near 0).
Eigen::MatrixXd CovarianceFromInformation(const Eigen::MatrixXd& information, double factor) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(information);
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(information.rows(), information.cols());
  for (int k = 0; k < information.rows(); ++k) {
    const double lambda = eigen.eigenvalues()[k];
    const double variance =
        lambda * kUnobservableVariance > 1 ? std::min(factor / lambda, kMaxVariance) : kMaxVariance;
    covariance += variance * eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).transpose();
  }
  return covariance;
}

// Sum over groups of clusters of (sum of the group's scores)(...)^T, with the small-sample factor
// G / (G - 1). `group[c]` < 0: cluster c is a group of its own.
Eigen::MatrixXd GroupedSandwich(const std::vector<Eigen::VectorXd>& scores,
                                const std::vector<int>& group) {
  std::map<int, Eigen::VectorXd> sums;
  int next_own = -1;
  for (size_t c = 0; c < scores.size(); ++c) {
    const int key = group.empty() || group[c] < 0 ? next_own-- : group[c];
    auto it = sums.find(key);
    if (it == sums.end()) {
      sums.emplace(key, scores[c]);
    } else {
      it->second += scores[c];
    }
  }
  const int n = scores.empty() ? 0 : static_cast<int>(scores.front().size());
  Eigen::MatrixXd sandwich = Eigen::MatrixXd::Zero(n, n);
  for (const auto& [key, sum] : sums) sandwich += sum * sum.transpose();
  const double num_groups = static_cast<double>(sums.size());
  return num_groups > 1 ? Eigen::MatrixXd(sandwich * num_groups / (num_groups - 1)) : sandwich;
}

// Cluster-robust (sandwich) covariance of T_e's free tangent, X = H^-1 E (E selects T_e),
// v_c = (J_c X)^T r_c over the data rows, and T_e's response to each of the stereo depth's
// consider parameters s (its scale and disparity bias field), dx = -H^-1 J^T dr/ds. H includes the
// regularisers (they keep it invertible); their rows add no score.
// With group keys (two-way clustering, Cameron, Gelbach & Miller 2011): V = V_A + [V_B - V_AB]+, with
// A the clusters merged by their first group key (the landmark), B by their second (one sensor's
// capture at one station), AB the clusters themselves. V_B - V_AB estimates the variance that
// errors shared within the second groups add; [.]+ keeps its nonnegative eigenvalues, as a variance
// component's estimate is truncated at zero: with few stations, the station sums (partly absorbed
// by the stations' own poses) would otherwise take away from the landmark clusters' variance.
// Per data term, the sum of its clusters' scores and their scatter (sum of s s^T).
struct TermScores {
  std::vector<Eigen::VectorXd> sums;
  std::vector<Eigen::MatrixXd> scatters;
};

struct ClusterRobustCovariance {
  Eigen::MatrixXd sandwich;              // in the parameters' own units
  Eigen::MatrixXd consider_sensitivity;  // dT_e / d(consider parameters), one column each
  TermScores term_scores;
};

// The scores summed per term (none without terms).
TermScores SumScoresByTerm(const std::vector<Eigen::VectorXd>& scores,
                           const ExtrinsicUncertaintyInputs& inputs) {
  TermScores terms;
  if (inputs.cluster_term.size() != scores.size() || scores.empty()) return terms;
  const Eigen::Index n = scores.front().size();
  terms.sums.assign(inputs.term_names.size(), Eigen::VectorXd::Zero(n));
  terms.scatters.assign(inputs.term_names.size(), Eigen::MatrixXd::Zero(n, n));
  for (size_t c = 0; c < scores.size(); ++c) {
    const int term = inputs.cluster_term[c];
    terms.sums.at(term) += scores[c];
    terms.scatters.at(term) += scores[c] * scores[c].transpose();
  }
  return terms;
}

std::optional<ClusterRobustCovariance> ClusterRobust(const JacobianRows& rows,
                                                     const Eigen::SparseMatrix<double>& information,
                                                     int num_other,
                                                     const ExtrinsicUncertaintyInputs& inputs) {
  const std::vector<std::array<int, 2>>& cluster_groups = inputs.cluster_groups;
  const size_t num_clusters = inputs.clusters.size();
  ClusterRobustCovariance robust;
  Eigen::MatrixXd* sandwich = &robust.sandwich;
  Eigen::MatrixXd* consider_sensitivity = &robust.consider_sensitivity;
  const int num_cols = static_cast<int>(information.cols());
  const int num_extrinsic = num_cols - num_other;
  Eigen::SparseMatrix<double> regularised = information;
  for (int i = 0; i < num_cols; ++i) regularised.coeffRef(i, i) += 1e-12;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> full(regularised);
  if (full.info() != Eigen::Success || num_clusters < 2) return std::nullopt;
  Eigen::MatrixXd selector = Eigen::MatrixXd::Zero(num_cols, num_extrinsic);
  for (int a = 0; a < num_extrinsic; ++a) selector(num_other + a, a) = 1;
  const Eigen::MatrixXd y = rows.jacobian * full.solve(selector);
  std::vector<Eigen::VectorXd> scores(num_clusters, Eigen::VectorXd::Zero(num_extrinsic));
  *consider_sensitivity = Eigen::MatrixXd::Zero(num_extrinsic, 4);
  Eigen::MatrixXd known = Eigen::MatrixXd::Zero(num_extrinsic, num_extrinsic);
  for (int row = 0; row < rows.num_data_rows; ++row) {
    if (rows.cluster[row] == kMeasurementRow) {
      known += y.row(row).transpose() * y.row(row);
      continue;
    }
    scores[rows.cluster[row]] += y.row(row).transpose() * rows.residuals[row];
    *consider_sensitivity -= y.row(row).transpose() * rows.consider_derivative[row].transpose();
  }
  robust.term_scores = SumScoresByTerm(scores, inputs);
  *sandwich = GroupedSandwich(scores, {});
  if (!cluster_groups.empty()) {
    std::vector<int> first(num_clusters), second(num_clusters);
    for (size_t c = 0; c < num_clusters; ++c) {
      first[c] = cluster_groups[c][0];
      second[c] = cluster_groups[c][1];
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> shared(GroupedSandwich(scores, second) -
                                                          *sandwich);
    *sandwich = GroupedSandwich(scores, first) +
                shared.eigenvectors() * shared.eigenvalues().cwiseMax(0.0).asDiagonal() *
                    shared.eigenvectors().transpose();
  }
  *sandwich += known;
  if (!sandwich->allFinite()) return std::nullopt;
  return robust;
}

// One sentence per direction whose standard deviation exceeds the thresholds.
std::vector<std::string> NameUnobservable(const ExtrinsicUncertainty& result,
                                          const MotionAnalysis& motion,
                                          const ObservabilityOptions& options) {
  std::vector<std::string> sentences;
  for (int k = 5; k >= 0; --k) {
    const Eigen::Matrix<double, 6, 1> v = result.eigenvectors.col(k);
    const double sigma = result.eigenvalues[k];
    const bool translation = v.tail<3>().squaredNorm() >= 0.5;
    const double threshold =
        translation ? options.unobservable_translation_mm : options.unobservable_rotation_deg;
    if (!(sigma > threshold)) continue;
    std::ostringstream sentence;
    sentence << std::setprecision(3);
    if (translation) {
      sentence << "translation along " << DescribeAxis(v.tail<3>()) << " is unobservable (sigma "
               << sigma << " mm): ";
    } else {
      sentence << "rotation about " << DescribeAxis(v.head<3>()) << " is unobservable (sigma "
               << sigma << " deg): ";
    }
    sentence << Advice(motion);
    sentences.push_back(sentence.str());
  }
  return sentences;
}

// The cluster-robust (sandwich) covariance of T_e with the stereo scale's consider term, into
// result->covariance where the sandwich can be formed; the formal one stays otherwise.
void AddClusterRobustCovariance(const JacobianRows& rows,
                                const Eigen::SparseMatrix<double>& information,
                                const ColumnLayout& layout,
                                const ExtrinsicUncertaintyInputs& inputs,
                                const ObservabilityOptions& options,
                                ExtrinsicUncertainty* result) {
  const std::optional<ClusterRobustCovariance> cluster_robust =
      ClusterRobust(rows, information, layout.num_other, inputs);
  if (!cluster_robust) return;
  const Eigen::MatrixXd& sandwich = cluster_robust->sandwich;
  const Eigen::MatrixXd to_reported = layout.directions * layout.scale.asDiagonal();
  const Eigen::MatrixXd reported_sensitivity = to_reported * cluster_robust->consider_sensitivity;
  const TermScores& terms = cluster_robust->term_scores;
  for (size_t t = 0; t < terms.sums.size(); ++t) {
    TermPull pull;
    pull.term = inputs.term_names[t];
    pull.pull = -to_reported * terms.sums[t];  // the term's presence moves T_e
    const Eigen::VectorXd scatter =
        (to_reported * terms.scatters[t] * to_reported.transpose()).diagonal().cwiseSqrt();
    for (int k = 0; k < 6; ++k) {
      pull.significance[k] = scatter[k] > 0 ? pull.pull[k] / scatter[k] : 0.0;
    }
    result->term_pulls.push_back(pull);
  }
  result->stereo_scale_sensitivity = reported_sensitivity.col(0);
  result->disparity_bias_sensitivity = reported_sensitivity.rightCols<3>();
  Matrix6 robust = ToReported(ScaleTangent(sandwich, layout, 1), layout);
  // Directions the data leaves undetermined keep the formal (capped) variance.
  Eigen::SelfAdjointEigenSolver<Matrix6> formal(result->formal_covariance);
  for (int k = 0; k < 6; ++k) {
    if (formal.eigenvalues()[k] > kUnobservableVariance) {
      robust += formal.eigenvalues()[k] * formal.eigenvectors().col(k) *
                formal.eigenvectors().col(k).transpose();
    }
  }
  const Matrix6 scale =
      result->stereo_scale_sensitivity * result->stereo_scale_sensitivity.transpose();
  const Matrix6 field =
      result->disparity_bias_sensitivity * result->disparity_bias_sensitivity.transpose();
  result->covariance = robust + options.stereo_scale_sigma * options.stereo_scale_sigma * scale +
                       options.disparity_bias_sigma_px * options.disparity_bias_sigma_px * field;
  result->cluster_robust = true;
  result->num_clusters = static_cast<int>(inputs.clusters.size());
}

// The directions held because the data do not determine them: one sentence each (before the others:
// their standard deviation is unbounded), the camera axes lying mostly in them marked undetermined.
void NameUndetermined(const ExtrinsicUncertaintyInputs& inputs,
                      const MotionAnalysis& motion,
                      ExtrinsicUncertainty* result) {
  std::vector<std::string> sentences;
  for (int block = 0; block < 2; ++block) {
    const Eigen::Matrix3d& held =
        block == 0 ? inputs.undetermined_rotation : inputs.undetermined_translation;
    const Eigen::MatrixXd directions = HeldDirectionsOf(held);
    for (int k = 0; k < directions.cols(); ++k) {
      sentences.push_back((block == 0 ? "rotation about " : "translation along ") +
                          DescribeAxis(directions.col(k)) +
                          " is unobservable (held, no sigma): " + Advice(motion));
    }
    for (int axis = 0; axis < 3; ++axis) {
      result->undetermined[3 * block + axis] = held(axis, axis) > 0.5;
    }
  }
  result->unobservable.insert(result->unobservable.begin(), sentences.begin(), sentences.end());
  const auto is_translation = [](const std::string& sentence) {
    return sentence.rfind("translation along ", 0) == 0;
  };
  if (std::count_if(result->unobservable.begin(), result->unobservable.end(), is_translation) ==
      3) {
    result->unobservable.insert(
        result->unobservable.begin(),
        "all translation of cam_from_lidar is unobservable: " + Advice(motion));
  }
}

}  // namespace

std::string UncertaintyCaveat(const MotionAnalysis& motion, bool moving_platform) {
  if (!moving_platform || motion.unique) return "";
  const std::string axis = motion.common_axis_in_cam.norm() > 0.5
                               ? DescribeAxis(motion.common_axis_in_cam)
                               : std::string("no turn of 2 deg");
  return "not validated for a moving platform turning about one axis (" + axis +
         "): the model leaves out errors common to the whole drive, which such a drive does not "
         "average out: the cameras' systematic error of the direction of travel (the road's "
         "keypoint offsets; a drive that does not turn passes it on to cam_from_lidar's "
         "rotation), the LiDAR's and the stereo depth's; read these sigmas as lower bounds "
         "(docs/benchmarks/uncertainty_drives.md and travel_direction.md give the coverage "
         "measured on drives)";
}

ExtrinsicUncertainty ComputeExtrinsicUncertainty(const ExtrinsicUncertaintyInputs& inputs,
                                                 const MotionAnalysis& motion,
                                                 const ObservabilityOptions& options) {
  ceres::Problem* problem = inputs.problem;
  double* cam_from_lidar_rotation = inputs.cam_from_lidar_rotation;
  double* cam_from_lidar_translation = inputs.cam_from_lidar_translation;
  const auto& clusters = inputs.clusters;
  ExtrinsicUncertainty result;
  const bool rotation_free = problem->HasParameterBlock(cam_from_lidar_rotation) &&
                             !problem->IsParameterBlockConstant(cam_from_lidar_rotation);
  const bool translation_free = problem->HasParameterBlock(cam_from_lidar_translation) &&
                                !problem->IsParameterBlockConstant(cam_from_lidar_translation);
  if (!rotation_free && !translation_free) {
    result.message = "cam_from_lidar is held constant in this mode";
    return result;
  }
  const ColumnLayout layout = MakeColumnLayout(inputs, rotation_free, translation_free);
  const JacobianRows rows = EvaluateRows(problem,
                                         layout,
                                         clusters,
                                         inputs.regularizers,
                                         inputs.measurements,
                                         inputs.depth_consider_derivative);
  const Eigen::SparseMatrix<double> data_jacobian = rows.jacobian.topRows(rows.num_data_rows);
  const Eigen::SparseMatrix<double> data_information = NormalMatrix(data_jacobian);
  const Eigen::SparseMatrix<double> information = NormalMatrix(rows.jacobian);
  Eigen::MatrixXd marginal;
  if (!MarginalInformation(data_information, layout.num_other, &marginal)) {
    result.message =
        "the joint problem's information matrix is singular without T_e (a gauge freedom besides "
        "T_e)";
    return result;
  }
  // Formal covariance from the data alone (no prior); held directions are no parameters.
  double squared_norm = 0;
  for (int row = 0; row < rows.num_data_rows; ++row)
    squared_norm += rows.residuals[row] * rows.residuals[row];
  const int redundancy = rows.num_data_rows + static_cast<int>(inputs.hidden_residuals) -
                         static_cast<int>(information.cols());
  result.variance_factor = redundancy > 0 ? squared_norm / redundancy : 1.0;
  result.formal_covariance = ToReported(
      CovarianceFromInformation(ScaleTangent(marginal, layout, -1), result.variance_factor),
      layout);
  result.covariance = result.formal_covariance;

  AddClusterRobustCovariance(rows, information, layout, inputs, options, &result);

  Eigen::SelfAdjointEigenSolver<Matrix6> eigen(result.covariance);
  for (int k = 0; k < 6; ++k) {  // ascending: standard deviations ascending
    result.eigenvalues[k] = std::sqrt(std::max(eigen.eigenvalues()[k], 0.0));
    result.eigenvectors.col(k) = eigen.eigenvectors().col(k);
  }
  result.computed = true;
  result.unobservable = NameUnobservable(result, motion, options);
  NameUndetermined(inputs, motion, &result);
  SetPullSigmas(result.covariance, result.undetermined, &result.term_pulls);
  result.term_disagreements = DescribeTermDisagreements(result.term_pulls);
  return result;
}

}  // namespace colmap_lidar
