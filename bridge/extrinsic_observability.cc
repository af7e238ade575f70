#include "bridge/extrinsic_observability.h"

#include "colmap_ext/logging.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <ceres/cost_function.h>
#include <ceres/crs_matrix.h>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace colmap_lidar {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

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
  CHECK_OPTION_GT(max_parallel_axes_deg, 0);
  return true;
}

MotionAnalysis AnalyseMotion(const colmap::Reconstruction& reconstruction,
                             const ObservabilityOptions& options) {
  MotionAnalysis analysis;
  const std::vector<colmap::image_t>& ids = reconstruction.RegImageIds();
  analysis.num_stations = static_cast<int>(ids.size());
  std::vector<Eigen::Vector3d> axes;
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
      if (angle_axis.angle() > largest_angle) {
        largest_angle = angle_axis.angle();
        analysis.common_axis_in_cam = angle_axis.axis();
      }
    }
  }
  analysis.num_rotating_pairs = static_cast<int>(axes.size());
  for (size_t a = 0; a < axes.size(); ++a) {
    for (size_t b = a + 1; b < axes.size(); ++b) {
      const double cosine = std::min(1.0, std::abs(axes[a].dot(axes[b])));
      analysis.max_axis_angle_deg =
          std::max(analysis.max_axis_angle_deg, std::acos(cosine) * kRadToDeg);
    }
  }
  analysis.unique =
      analysis.num_stations >= 3 && analysis.max_axis_angle_deg > options.max_parallel_axes_deg;
  std::ostringstream verdict;
  verdict << std::fixed << std::setprecision(1);
  if (analysis.num_stations < 3) {
    verdict << "only " << analysis.num_stations
            << " stations: the seed's uniqueness condition needs at least 3";
  } else if (analysis.num_rotating_pairs == 0) {
    verdict << "the stations do not rotate relative to each other: T_e's "
               "rotation follows from the translations, its translation is "
               "unobservable";
  } else if (!analysis.unique) {
    verdict << "all relative rotations share one axis ("
            << DescribeAxis(analysis.common_axis_in_cam) << ", axes within "
            << analysis.max_axis_angle_deg
            << " deg): T_e's translation along it is unobservable; add "
               "stations tilted about a second axis";
  } else {
    verdict << "relative rotation axes of " << analysis.num_rotating_pairs << " station pairs span "
            << analysis.max_axis_angle_deg << " deg: T_e is unique (the seed's condition holds)";
  }
  analysis.verdict = verdict.str();
  return analysis;
}

ExtrinsicUncertainty ComputeExtrinsicUncertainty(
    ceres::Problem* problem,
    double* cam_from_lidar_rotation,
    double* cam_from_lidar_translation,
    const std::array<bool, 3>& held_translation,
    const std::vector<std::vector<ceres::ResidualBlockId>>& clusters,
    const std::unordered_map<ceres::ResidualBlockId, double>& depth_scale_derivative,
    const MotionAnalysis& motion,
    const ObservabilityOptions& options) {
  ExtrinsicUncertainty result;
  const bool rotation_free = problem->HasParameterBlock(cam_from_lidar_rotation) &&
                             !problem->IsParameterBlockConstant(cam_from_lidar_rotation);
  const bool translation_free = problem->HasParameterBlock(cam_from_lidar_translation) &&
                                !problem->IsParameterBlockConstant(cam_from_lidar_translation);
  if (!rotation_free && !translation_free) {
    result.message = "cam_from_lidar is held constant in this mode";
    return result;
  }
  // Variable blocks, T_e last.
  std::vector<double*> blocks;
  problem->GetParameterBlocks(&blocks);
  std::vector<double*> ordered;
  int num_other = 0;
  for (double* block : blocks) {
    if (block == cam_from_lidar_rotation || block == cam_from_lidar_translation ||
        problem->IsParameterBlockConstant(block)) {
      continue;
    }
    ordered.push_back(block);
    num_other += problem->ParameterBlockTangentSize(block);
  }
  // Tangent index -> 6-vector index (rotation 0..2, translation 3..5).
  std::vector<int> extrinsic_index;
  if (rotation_free) {
    ordered.push_back(cam_from_lidar_rotation);
    extrinsic_index.insert(extrinsic_index.end(), {0, 1, 2});
  }
  if (translation_free) {
    ordered.push_back(cam_from_lidar_translation);
    for (int i = 0; i < 3; ++i) {
      if (!held_translation[i]) extrinsic_index.push_back(3 + i);
    }
  }
  const int num_extrinsic = static_cast<int>(extrinsic_index.size());

  // Rows in cluster order.
  std::vector<ceres::ResidualBlockId> residual_blocks;
  std::vector<int> row_cluster;
  std::vector<double> row_scale_derivative;
  for (size_t c = 0; c < clusters.size(); ++c) {
    for (const ceres::ResidualBlockId id : clusters[c]) {
      residual_blocks.push_back(id);
      const int num_residuals = problem->GetCostFunctionForResidualBlock(id)->num_residuals();
      row_cluster.insert(row_cluster.end(), num_residuals, static_cast<int>(c));
      const auto derivative = depth_scale_derivative.find(id);
      row_scale_derivative.insert(
          row_scale_derivative.end(),
          num_residuals,
          derivative == depth_scale_derivative.end() ? 0.0 : derivative->second);
    }
  }
  ceres::Problem::EvaluateOptions evaluate_options;
  evaluate_options.parameter_blocks = ordered;
  evaluate_options.residual_blocks = residual_blocks;
  evaluate_options.num_threads = 2;
  double cost = 0;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  problem->Evaluate(evaluate_options, &cost, &residuals, nullptr, &crs);
  THROW_CHECK_EQ(static_cast<size_t>(crs.num_rows), row_cluster.size());
  THROW_CHECK_EQ(crs.num_cols, num_other + num_extrinsic);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(crs.values.size());
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) {
      triplets.emplace_back(row, crs.cols[k], crs.values[k]);
    }
  }
  Eigen::SparseMatrix<double> jacobian(crs.num_rows, crs.num_cols);
  jacobian.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::SparseMatrix<double> information = (jacobian.transpose() * jacobian).pruned();

  // Schur complement: information of T_e with every other block marginalised.
  Eigen::SparseMatrix<double> other = information.topLeftCorner(num_other, num_other);
  for (int i = 0; i < num_other; ++i) other.coeffRef(i, i) += 1e-12;
  const Eigen::MatrixXd coupling =
      Eigen::MatrixXd(information.bottomLeftCorner(num_extrinsic, num_other));
  const Eigen::MatrixXd extrinsic =
      Eigen::MatrixXd(information.bottomRightCorner(num_extrinsic, num_extrinsic));
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(other);
  if (ldlt.info() != Eigen::Success) {
    result.message =
        "the joint problem's information matrix is singular "
        "without T_e (a gauge freedom besides T_e)";
    return result;
  }
  const Eigen::MatrixXd marginal =
      extrinsic - coupling * ldlt.solve(Eigen::MatrixXd(coupling.transpose()));

  // In (deg, mm) units; held components are known exactly (huge information).
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Zero();
  for (int i = 0; i < 6; ++i) info(i, i) = 1e30;
  const auto unit = [](int index) { return index < 3 ? kRadToDeg : 1000.0; };
  for (int a = 0; a < num_extrinsic; ++a) {
    for (int b = 0; b < num_extrinsic; ++b) {
      info(extrinsic_index[a], extrinsic_index[b]) =
          marginal(a, b) / (unit(extrinsic_index[a]) * unit(extrinsic_index[b]));
    }
  }
  const int redundancy = crs.num_rows - crs.num_cols;
  result.variance_factor = redundancy > 0 ? 2 * cost / redundancy : 1.0;
  // Formal covariance: the pseudo-inverse of the marginal information (unobservable -> huge).
  const auto covariance_from_information = [](const Eigen::Matrix<double, 6, 6>& information,
                                              double factor) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(information);
    Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
    for (int k = 0; k < 6; ++k) {
      const double lambda = std::max(eigen.eigenvalues()[k], 1e-30);
      covariance +=
          factor / lambda * eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).transpose();
    }
    return covariance;
  };
  result.formal_covariance = covariance_from_information(info, result.variance_factor);
  result.covariance = result.formal_covariance;

  // Cluster-robust (sandwich) covariance: X = H^-1 E (E selects T_e), v_c = (J_c X)^T r_c.
  Eigen::SparseMatrix<double> regularised = information;
  for (int i = 0; i < regularised.rows(); ++i) regularised.coeffRef(i, i) += 1e-12;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> full(regularised);
  if (full.info() == Eigen::Success && clusters.size() > 1) {
    Eigen::MatrixXd selector = Eigen::MatrixXd::Zero(crs.num_cols, num_extrinsic);
    for (int a = 0; a < num_extrinsic; ++a) selector(num_other + a, a) = 1;
    const Eigen::MatrixXd x = full.solve(selector);
    const Eigen::MatrixXd y = jacobian * x;
    std::vector<Eigen::VectorXd> scores(clusters.size(), Eigen::VectorXd::Zero(num_extrinsic));
    Eigen::VectorXd scale_sensitivity = Eigen::VectorXd::Zero(num_extrinsic);
    for (int row = 0; row < crs.num_rows; ++row) {
      scores[row_cluster[row]] += y.row(row).transpose() * residuals[row];
      // dx = -H^-1 J^T dr/ds: T_e's response to a common stereo scale error.
      scale_sensitivity -= y.row(row).transpose() * row_scale_derivative[row];
    }
    for (int a = 0; a < num_extrinsic; ++a) {
      result.stereo_scale_sensitivity[extrinsic_index[a]] =
          scale_sensitivity[a] * unit(extrinsic_index[a]);
    }
    const double num_clusters = static_cast<double>(clusters.size());
    Eigen::MatrixXd sandwich = Eigen::MatrixXd::Zero(num_extrinsic, num_extrinsic);
    for (const Eigen::VectorXd& score : scores) sandwich += score * score.transpose();
    sandwich *= num_clusters / (num_clusters - 1);
    if (sandwich.allFinite()) {
      Eigen::Matrix<double, 6, 6> robust = Eigen::Matrix<double, 6, 6>::Zero();
      for (int a = 0; a < num_extrinsic; ++a) {
        for (int b = 0; b < num_extrinsic; ++b) {
          robust(extrinsic_index[a], extrinsic_index[b]) =
              sandwich(a, b) * unit(extrinsic_index[a]) * unit(extrinsic_index[b]);
        }
      }
      // Directions the formal information calls unobservable stay unobservable.
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> formal(result.formal_covariance);
      for (int k = 0; k < 6; ++k) {
        if (formal.eigenvalues()[k] > 1e6) {
          robust += formal.eigenvalues()[k] * formal.eigenvectors().col(k) *
                    formal.eigenvectors().col(k).transpose();
        }
      }
      result.covariance = robust + options.stereo_scale_sigma * options.stereo_scale_sigma *
                                       result.stereo_scale_sensitivity *
                                       result.stereo_scale_sensitivity.transpose();
      result.cluster_robust = true;
      result.num_clusters = static_cast<int>(clusters.size());
    }
  }

  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(result.covariance);
  for (int k = 0; k < 6; ++k) {  // eigen values ascending: store std devs ascending
    result.eigenvalues[k] = std::sqrt(std::max(eigen.eigenvalues()[k], 0.0));
    result.eigenvectors.col(k) = eigen.eigenvectors().col(k);
  }
  result.computed = true;

  int num_unobservable_translation = 0;
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
      ++num_unobservable_translation;
      sentence << "translation along " << DescribeAxis(v.tail<3>()) << " is unobservable (sigma "
               << sigma << " mm): ";
    } else {
      sentence << "rotation about " << DescribeAxis(v.head<3>()) << " is unobservable (sigma "
               << sigma << " deg): ";
    }
    sentence << Advice(motion);
    result.unobservable.push_back(sentence.str());
  }
  if (num_unobservable_translation == 3) {
    result.unobservable.insert(
        result.unobservable.begin(),
        "all translation of cam_from_lidar is unobservable: " + Advice(motion));
  }
  return result;
}

}  // namespace colmap_lidar
