// A 3D k-d tree over a std::vector<Eigen::Vector3d> that it does not copy: the vector must outlive the
// tree and stay unchanged. Built once in the constructor; queries are const and thread-safe.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace colmap_lidar {

class KdTree3 {
 public:
  explicit KdTree3(const std::vector<Eigen::Vector3d>& points);
  ~KdTree3();
  KdTree3(const KdTree3&) = delete;
  KdTree3& operator=(const KdTree3&) = delete;

  // Index of the nearest point and its squared distance; false if the tree is empty.
  bool Nearest(const Eigen::Vector3d& query, size_t* index, double* squared_distance) const;
  // The k nearest points (fewer if the tree is smaller), closest first.
  void KNearest(const Eigen::Vector3d& query,
                size_t k,
                std::vector<size_t>* indices,
                std::vector<double>* squared_distances) const;
  // All points within `radius` (not squared), unsorted.
  void RadiusSearch(const Eigen::Vector3d& query,
                    double radius,
                    std::vector<size_t>* indices) const;

  size_t Size() const { return points_.size(); }

 private:
  struct Impl;
  const std::vector<Eigen::Vector3d>& points_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace colmap_lidar
