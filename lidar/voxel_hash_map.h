// The local map of LiDAR odometry (Vizzo et al., "KISS-ICP", RA-L 2023, Sec. III-D): points in the
// world frame, kept in a hash of voxels of edge `voxel_size` holding at most `max_points_per_voxel`
// points each (a new point enters only a voxel with room: the map keeps its oldest points, spread
// by construction), voxels farther than `max_distance` from the sensor dropped. The nearest map point
// of a query is searched among the 27 voxels around it. Each voxel knows the shape of its points
// (PCA, redone when points enter): a plane (with its normal), a line (the arc of one scan line: its
// spread across the line is the scanner's pattern, not the surface's), scattered, or sparse (fewer
// than five points: too few to tell which).
#pragma once

#include <Eigen/Core>

#include <unordered_map>
#include <vector>

namespace colmap_lidar {

enum class VoxelShape { kScattered, kPlane, kLine, kSparse };

struct MapNeighbor {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double distance = 0;
  VoxelShape shape = VoxelShape::kScattered;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // of a plane
  // Which map point: its voxel and its place there (-1: none found).
  Eigen::Vector3i voxel = Eigen::Vector3i::Zero();
  int index = -1;
};

class VoxelHashMap {
 public:
  // Throws std::invalid_argument for a non-positive size, distance or count.
  VoxelHashMap(double voxel_size, double max_distance, int max_points_per_voxel);

  // Adds the points (world frame), then drops the voxels farther than max_distance from `origin`.
  void Update(const std::vector<Eigen::Vector3d>& points_in_world, const Eigen::Vector3d& origin);

  // The nearest map point among the 27 voxels around `query`, with its voxel's shape; false when
  // they are empty.
  bool NearestNeighbor(const Eigen::Vector3d& query, MapNeighbor* neighbor) const;

  // For each found neighbour (index >= 0), the shape of the map around its point: the points within
  // one voxel size of it among the 27 voxels around, which span several scan lines where one voxel
  // holds the arc of one. Sets shape and normal. Each map point's shape is computed once and kept
  // until a voxel among the 27 around its own changes; the voxels to compute are done in parallel.
  void ClassifyNeighbourhoods(std::vector<MapNeighbor>* neighbors);

  double VoxelSize() const { return voxel_size_; }
  bool Empty() const { return voxels_.empty(); }

 private:
  struct VoxelHash {
    size_t operator()(const Eigen::Vector3i& voxel) const;
  };
  Eigen::Vector3i VoxelOf(const Eigen::Vector3d& point) const;

  double voxel_size_;
  double max_distance_;
  size_t max_points_per_voxel_;
  struct PointShape {
    VoxelShape shape = VoxelShape::kSparse;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    int generation = -1;  // the voxel's generation it was computed in
    bool queued = false;  // within one ClassifyNeighbourhoods
  };
  struct Voxel {
    std::vector<Eigen::Vector3d> points;
    VoxelShape shape = VoxelShape::kScattered;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    bool changed = false;  // within one Update
    // The shape of the map around each point (ClassifyNeighbourhoods), valid while computed in the
    // current generation, which a change among the 27 voxels around ends.
    std::vector<PointShape> point_shapes;
    int generation = 0;
  };
  // Calls visit(voxel) for each occupied voxel of the 27 around `point`'s.
  template <typename Visit>
  void ForEachVoxelAround(const Eigen::Vector3d& point, const Visit& visit) const;
  // The shape of the map around point `index` of `voxel`.
  void ClassifyPoint(Voxel* voxel, int index) const;
  // Ends the generation of the voxel `key` and of the 26 around it.
  void InvalidateAround(const Eigen::Vector3i& key);

  std::unordered_map<Eigen::Vector3i, Voxel, VoxelHash> voxels_;
};

// One point per occupied voxel of edge `voxel_size`: the first point that falls into it (in input
// order, so the result does not depend on the hash's order). KISS-ICP's subsampling: the kept points
// are measured ones, not averages, and the pass is a single hash lookup per point.
std::vector<Eigen::Vector3d> FirstPointPerVoxel(const std::vector<Eigen::Vector3d>& points,
                                                double voxel_size);

}  // namespace colmap_lidar
