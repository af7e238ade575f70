// Ceres' GradientChecker for the cost-function unit tests: the analytic (or autodiff) Jacobians of a
// cost at given parameter blocks against numeric differences, one manifold (or nullptr) per block.
#pragma once

#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <vector>

namespace colmap_lidar {
namespace testing {

// Success, or the checker's error log; `results` (optional) gets the probe's details.
inline ::testing::AssertionResult GradientMatchesNumericDifferences(
    const ceres::CostFunction& cost,
    std::vector<double*> blocks,
    const std::vector<const ceres::Manifold*>& manifolds,
    ceres::GradientChecker::ProbeResults* results = nullptr) {
  ceres::GradientChecker checker(&cost, &manifolds, ceres::NumericDiffOptions());
  ceres::GradientChecker::ProbeResults own;
  ceres::GradientChecker::ProbeResults* probe = results != nullptr ? results : &own;
  if (checker.Probe(blocks.data(), 1e-7, probe)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << probe->error_log;
}

}  // namespace testing
}  // namespace colmap_lidar
