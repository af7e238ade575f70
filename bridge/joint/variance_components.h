// Variance-component estimation (Foerstner 1979; Koch, "Parameter Estimation and Hypothesis Testing in
// Linear Models", ch. 3.6): each data group g of a least-squares problem (reprojection, depth priors,
// E_l, E_m) has an unknown variance factor s_g^2 by which its nominal variances are off. With the
// residuals whitened by the current weights,
//   s_g^2 = Omega_g / r_g,  Omega_g = sum of the group's squared whitened residuals,
//   r_g = n_g - tr(H^-1 H_g),  H = sum_g H_g (+ priors), H_g = J_g^T J_g,
// and the redundancy numbers r_g sum to the total redundancy n - u. Iterated with the solve (each
// group's weights divided by its factor), the factors converge to 1.
//
// tr(H^-1 H_g) is evaluated block-diagonally: H^-1 is replaced by the inverse of each parameter
// block's own diagonal block of H. A landmark's three coordinates are then shared exactly between its
// reprojections, depth priors and E_m in proportion to their information; what the approximation
// leaves out is the coupling between blocks (a landmark's share of its cameras' uncertainty), which
// moves parameters between groups' shares but not their sum.
//
// A group's observation count n_g is its number of original samples: a compressed E_l block
// (bridge/joint/lidar_pair_cost.h) stands for all its point-to-plane residuals in 13 rows of the
// same cost and Gauss-Newton information.
#pragma once

#include <ceres/problem.h>

#include <string>
#include <vector>

namespace colmap_lidar {

struct VarianceGroup {
  std::string name;
  std::vector<ceres::ResidualBlockId> blocks;
  // Original samples the blocks stand for (>= their residual rows).
  size_t num_observations = 0;
};

struct VarianceComponent {
  std::string name;
  size_t num_observations = 0;
  // tr(H^-1 H_g): the parameters this group determines.
  double parameter_share = 0;
  double redundancy = 0;
  // Omega_g: twice the group's cost at the current weights.
  double squared_norm = 0;
  // Omega_g / r_g (1 if the group has no redundancy).
  double factor = 1;
};

// The variance components of `groups` at the problem's current state and weights. `fixed`: residual
// blocks with known variances (priors); they add information to H but get no factor. Blocks held
// constant carry no parameters.
std::vector<VarianceComponent> EstimateVarianceComponents(
    ceres::Problem* problem,
    const std::vector<VarianceGroup>& groups,
    const std::vector<ceres::ResidualBlockId>& fixed);

}  // namespace colmap_lidar
