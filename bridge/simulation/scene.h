// Procedural scenes for the simulator: a scanned structure (boxes and vertical cylinders) on a ground
// plane, inside a courtyard of walls and other objects 5-15 m away. World frame: z up, metres, ground z=0.
// Surfaces carry a solid (3D) concrete-like texture, so every view of a point sees the same albedo.
#pragma once

#include "bridge/simulation/box_hierarchy.h"
#include "lidar/point_cloud.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace colmap_lidar {
namespace sim {

struct Primitive {
  enum class Type { kBox, kCylinder, kGround };
  Type type = Type::kBox;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();     // box/cylinder centre
  Eigen::Vector3d half_size = Eigen::Vector3d::Ones();  // box half extents; cylinder: (r, r, h/2)
  double yaw = 0;                                       // box rotation about world z [rad]
  bool is_object = false;  // part of the scanned structure (sampled into surface.ply)
  double albedo = 0.6;     // mean albedo in [0, 1]
  double texture_contrast = 0.45;
};

struct RayHit {
  double t = 0;                                      // distance along the unit ray
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, facing the ray
  int primitive = -1;
};

class Scene {
 public:
  // Scenes: t_specimen, square_pillar, cylinder_pillar, bridge_pier, street. Throws for an unknown
  // name. `street` is a straight street along world x (x from -20 to 120 m) between building facades
  // with setbacks, with parked cars, poles and trees, and cars driving along it (MovedTo).
  static Scene Create(const std::string& name);
  static std::vector<std::string> Names();

  // Closest hit with t in (1e-6, max_t) along origin + t * unit_direction.
  bool Intersect(const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& unit_direction,
                 double max_t,
                 RayHit* hit) const;

  // Albedo in [0, 1] of a surface point of primitive `primitive` (solid multi-scale texture).
  double Albedo(const Eigen::Vector3d& point_in_world, int primitive) const;
  // Lambertian grey level in [0, 255] under the scene's sun and ambient light.
  double Shade(const Eigen::Vector3d& point_in_world,
               const Eigen::Vector3d& normal,
               int primitive) const;

  // Points on the visible surface of the structure (faces inside other object primitives or below the
  // ground are dropped), on a grid of the given spacing, with outward normals.
  PointCloud SampleObjectSurface(double spacing) const;
  // True if the point lies on or inside an object primitive (within `tolerance`).
  bool InsideObject(const Eigen::Vector3d& point_in_world, double tolerance) const;

  // The scene at time `time_s` [s]: moving objects (the street's driving cars) at their positions.
  Scene MovedTo(double time_s) const;

  const std::string& Name() const { return name_; }
  const std::vector<Primitive>& Primitives() const { return primitives_; }
  // Where the stations look: centre of the structure and its horizontal radius and height.
  const Eigen::Vector3d& ObjectCenter() const { return object_center_; }
  double ObjectRadius() const { return object_radius_; }
  double ObjectHeight() const { return object_height_; }

 private:
  void AddBox(const Eigen::Vector3d& min_corner,
              const Eigen::Vector3d& max_corner,
              bool is_object,
              double albedo,
              double yaw = 0);
  void AddCylinder(const Eigen::Vector3d& base_center,
                   double radius,
                   double height,
                   bool is_object,
                   double albedo);
  // The ground plane z = 0 over [-half_extent_m, half_extent_m]^2.
  void AddGround(double half_extent_m, double albedo);
  void AddBackground();
  void AddStreet();
  void FinishObject();

  // Per primitive, for Intersect: its rotation (RotZ(yaw)) and padded world-aligned bounds, so that
  // a ray is tested against a primitive's exact shape only where it passes through its bounds.
  struct Frame {
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    AxisAlignedBox bounds;
  };
  static Frame FrameOf(const Primitive& primitive);
  // Appends the primitive and its frame, and indexes the scene again.
  void AddPrimitive(const Primitive& primitive);
  // The hierarchy over the bounded primitives (all but the ground planes, tested by every ray).
  void Index();

  struct Mover {
    size_t primitive = 0;
    Eigen::Vector3d center_at_zero = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s
  };
  std::vector<Mover> movers_;

  std::string name_;
  std::vector<Primitive> primitives_;
  std::vector<Frame> frames_;  // one per primitive
  BoxHierarchy hierarchy_;
  std::vector<int> bounded_;    // the primitive of each item of hierarchy_
  std::vector<int> unbounded_;  // the ground planes
  Eigen::Vector3d object_center_ = Eigen::Vector3d::Zero();
  double object_radius_ = 1;
  double object_height_ = 1;
  Eigen::Vector3d sun_direction_ = Eigen::Vector3d(0.4, -0.3, 0.866).normalized();
};

}  // namespace sim
}  // namespace colmap_lidar
