// The robust losses a least-squares problem of ours may put on its whitened residuals (Ceres'
// HuberLoss and CauchyLoss at a scale of the options' choosing).
#pragma once

namespace colmap_lidar {

enum class RobustLoss {
  kNone,    // plain squares
  kHuber,   // quadratic inside the scale, linear beyond
  kCauchy,  // log(1 + s^2): outliers' influence falls off
};

}  // namespace colmap_lidar
