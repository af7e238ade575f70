#include "bridge/simulation/scene.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>

namespace colmap_lidar {
namespace sim {
namespace {

constexpr double kEps = 1e-9;

// Hash of an integer lattice point to [0, 1).
double LatticeValue(int64_t x, int64_t y, int64_t z, uint32_t seed) {
  uint64_t h = static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ull ^
               static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4Full ^
               static_cast<uint64_t>(z) * 0x165667B19E3779F9ull ^
               (static_cast<uint64_t>(seed) << 32);
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ull;
  h ^= h >> 33;
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

// Smooth 3D value noise in [0, 1) with unit lattice spacing.
double ValueNoise(const Eigen::Vector3d& p, uint32_t seed) {
  const Eigen::Vector3d f = p.array().floor();
  const Eigen::Vector3d r = p - f;
  const Eigen::Vector3d s = r.array() * r.array() * (3.0 - 2.0 * r.array());
  const int64_t x = static_cast<int64_t>(f.x()), y = static_cast<int64_t>(f.y()),
                z = static_cast<int64_t>(f.z());
  double value = 0;
  for (int dz = 0; dz < 2; ++dz) {
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        const double w =
            (dx ? s.x() : 1 - s.x()) * (dy ? s.y() : 1 - s.y()) * (dz ? s.z() : 1 - s.z());
        value += w * LatticeValue(x + dx, y + dy, z + dz, seed);
      }
    }
  }
  return value;
}

double SmoothStep(double edge0, double edge1, double x) {
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

Eigen::Matrix3d RotZ(double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// `R`: RotZ(box.yaw).
bool IntersectBox(const Primitive& box,
                  const Eigen::Matrix3d& R,
                  const Eigen::Vector3d& origin,
                  const Eigen::Vector3d& dir,
                  double* t_hit,
                  Eigen::Vector3d* normal) {
  const Eigen::Vector3d o = R.transpose() * (origin - box.center);
  const Eigen::Vector3d d = R.transpose() * dir;
  double t_min = -1e300, t_max = 1e300;
  int axis_min = 0, axis_max = 0;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < kEps) {
      if (std::abs(o[i]) > box.half_size[i]) return false;
      continue;
    }
    double t1 = (-box.half_size[i] - o[i]) / d[i];
    double t2 = (box.half_size[i] - o[i]) / d[i];
    if (t1 > t2) std::swap(t1, t2);
    if (t1 > t_min) {
      t_min = t1;
      axis_min = i;
    }
    if (t2 < t_max) {
      t_max = t2;
      axis_max = i;
    }
  }
  if (t_max < t_min || t_max < 1e-6) return false;
  const bool entering = t_min > 1e-6;
  const int axis = entering ? axis_min : axis_max;
  *t_hit = entering ? t_min : t_max;
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  n[axis] = d[axis] > 0 ? -1 : 1;
  *normal = R * n;
  return true;
}

bool IntersectCylinder(const Primitive& cyl,
                       const Eigen::Vector3d& origin,
                       const Eigen::Vector3d& dir,
                       double* t_hit,
                       Eigen::Vector3d* normal) {
  const double r = cyl.half_size.x(), h = cyl.half_size.z();
  const Eigen::Vector3d o = origin - cyl.center;
  double best = 1e300;
  Eigen::Vector3d best_normal;
  const double a = dir.x() * dir.x() + dir.y() * dir.y();
  if (a > kEps) {
    const double b = o.x() * dir.x() + o.y() * dir.y();
    const double c = o.x() * o.x() + o.y() * o.y() - r * r;
    const double disc = b * b - a * c;
    if (disc >= 0) {
      const double sq = std::sqrt(disc);
      for (const double t : {(-b - sq) / a, (-b + sq) / a}) {
        if (t > 1e-6 && t < best && std::abs(o.z() + t * dir.z()) <= h) {
          best = t;
          best_normal = Eigen::Vector3d(o.x() + t * dir.x(), o.y() + t * dir.y(), 0) / r;
        }
      }
    }
  }
  if (std::abs(dir.z()) > kEps) {
    for (const double zc : {-h, h}) {
      const double t = (zc - o.z()) / dir.z();
      const Eigen::Vector3d p = o + t * dir;
      if (t > 1e-6 && t < best && p.x() * p.x() + p.y() * p.y() <= r * r) {
        best = t;
        best_normal = Eigen::Vector3d(0, 0, zc > 0 ? 1 : -1);
      }
    }
  }
  if (best == 1e300) return false;
  *t_hit = best;
  *normal = best_normal.dot(dir) > 0 ? -best_normal : best_normal;
  return true;
}

bool IntersectGround(const Primitive& ground,
                     const Eigen::Vector3d& origin,
                     const Eigen::Vector3d& dir,
                     double* t_hit,
                     Eigen::Vector3d* normal) {
  if (dir.z() > -kEps || origin.z() <= 0) return false;
  const double t = -origin.z() / dir.z();
  const Eigen::Vector3d p = origin + t * dir;
  if (std::abs(p.x()) > ground.half_size.x() || std::abs(p.y()) > ground.half_size.y()) {
    return false;
  }
  *t_hit = t;
  *normal = Eigen::Vector3d::UnitZ();
  return true;
}

}  // namespace

std::vector<std::string> Scene::Names() {
  return {"t_specimen", "square_pillar", "cylinder_pillar", "bridge_pier", "street"};
}

Scene Scene::Create(const std::string& name) {
  Scene scene;
  scene.name_ = name;
  if (name == "t_specimen") {
    // A T-shaped concrete specimen: a web 0.3 m thick under a 1.2 m wide flange.
    scene.AddBox({-0.15, -0.3, 0.0}, {0.15, 0.3, 0.9}, true, 0.62);
    scene.AddBox({-0.6, -0.3, 0.9}, {0.6, 0.3, 1.2}, true, 0.62);
  } else if (name == "square_pillar") {
    scene.AddBox({-0.3, -0.3, 0.0}, {0.3, 0.3, 2.4}, true, 0.6);
  } else if (name == "cylinder_pillar") {
    scene.AddCylinder({0, 0, 0}, 0.35, 2.4, true, 0.6);
  } else if (name == "bridge_pier") {
    scene.AddBox({-0.4, -0.6, 0.0}, {0.4, 0.6, 2.0}, true, 0.6);   // pier
    scene.AddBox({-0.6, -1.6, 2.0}, {0.6, 1.6, 2.5}, true, 0.63);  // cap beam
    for (const double y : {-1.1, 0.0, 1.1}) {                      // I-beams
      scene.AddBox({-1.5, y - 0.15, 2.5}, {1.5, y + 0.15, 2.56}, true, 0.55);
      scene.AddBox({-1.5, y - 0.03, 2.56}, {1.5, y + 0.03, 2.94}, true, 0.55);
      scene.AddBox({-1.5, y - 0.15, 2.94}, {1.5, y + 0.15, 3.0}, true, 0.55);
    }
  } else if (name == "street") {
    // The "structure" of a street is a bollard at the kerb (surface.ply stays small); the facades,
    // cars and trees are background.
    scene.AddCylinder({30, -5.2, 0}, 0.15, 1.0, true, 0.6);
    scene.FinishObject();
    scene.AddStreet();
    return scene;
  } else {
    std::string known;
    for (const std::string& n : Names()) known += " " + n;
    throw std::invalid_argument("Unknown scene '" + name + "'; known:" + known);
  }
  scene.FinishObject();
  scene.AddBackground();
  return scene;
}

void Scene::AddBox(const Eigen::Vector3d& min_corner,
                   const Eigen::Vector3d& max_corner,
                   bool is_object,
                   double albedo,
                   double yaw) {
  Primitive box;
  box.type = Primitive::Type::kBox;
  box.center = 0.5 * (min_corner + max_corner);
  box.half_size = 0.5 * (max_corner - min_corner);
  box.yaw = yaw;
  box.is_object = is_object;
  box.albedo = albedo;
  AddPrimitive(box);
}

void Scene::AddCylinder(const Eigen::Vector3d& base_center,
                        double radius,
                        double height,
                        bool is_object,
                        double albedo) {
  Primitive cyl;
  cyl.type = Primitive::Type::kCylinder;
  cyl.center = base_center + Eigen::Vector3d(0, 0, height / 2);
  cyl.half_size = Eigen::Vector3d(radius, radius, height / 2);
  cyl.is_object = is_object;
  cyl.albedo = albedo;
  AddPrimitive(cyl);
}

void Scene::AddGround(double half_extent_m, double albedo) {
  Primitive ground;
  ground.type = Primitive::Type::kGround;
  ground.half_size = Eigen::Vector3d(half_extent_m, half_extent_m, 0);
  ground.albedo = albedo;
  ground.texture_contrast = 0.5;
  AddPrimitive(ground);
}

Scene::Frame Scene::FrameOf(const Primitive& primitive) {
  // Padded beyond rounding, so that every hit of the exact test lies inside.
  constexpr double kPadding = 1e-6;
  Frame frame;
  if (primitive.type == Primitive::Type::kBox) frame.rotation = RotZ(primitive.yaw);
  const Eigen::Vector3d half_extent =
      frame.rotation.cwiseAbs() * primitive.half_size + Eigen::Vector3d::Constant(kPadding);
  frame.bounds = {primitive.center - half_extent, primitive.center + half_extent};
  return frame;
}

void Scene::AddPrimitive(const Primitive& primitive) {
  primitives_.push_back(primitive);
  frames_.push_back(FrameOf(primitive));
  Index();
}

void Scene::Index() {
  bounded_.clear();
  unbounded_.clear();
  std::vector<AxisAlignedBox> boxes;
  for (size_t i = 0; i < primitives_.size(); ++i) {
    if (primitives_[i].type == Primitive::Type::kGround) {
      unbounded_.push_back(static_cast<int>(i));
    } else {
      bounded_.push_back(static_cast<int>(i));
      boxes.push_back(frames_[i].bounds);
    }
  }
  hierarchy_ = BoxHierarchy(boxes);
}

void Scene::FinishObject() {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (const Primitive& p : primitives_) {
    lo = lo.cwiseMin(p.center - p.half_size);
    hi = hi.cwiseMax(p.center + p.half_size);
  }
  object_center_ = 0.5 * (lo + hi);
  object_radius_ = 0.5 * (hi - lo).head<2>().norm();
  object_height_ = hi.z();
}

void Scene::AddBackground() {
  AddGround(40, 0.45);
  // A courtyard: walls 10-14 m away and 3-5 m high (deliberately not symmetric: a square courtyard
  // would make LiDAR registration ambiguous under 90 degree turns, which real sites rarely are), and
  // objects 5-9 m away, so that clouds overlap widely.
  AddBox({-10.3, -11.3, 0}, {-10.0, 13.3, 4.0}, false, 0.5);
  AddBox({13.0, -11.3, 0}, {13.3, 13.3, 3.0}, false, 0.55);
  AddBox({-10.0, -11.3, 0}, {13.0, -11.0, 5.0}, false, 0.52);
  AddBox({-4.0, 12.4, 0}, {10.0, 12.7, 3.5}, false, 0.48, 0.12);  // skewed
  AddBox({5.0, 3.0, 0}, {7.0, 4.0, 1.5}, false, 0.4, 0.3);
  AddBox({-8.5, 5.5, 0}, {-5.5, 6.5, 2.0}, false, 0.5, -0.4);
  AddBox({3.5, -8.0, 0}, {5.0, -6.5, 1.0}, false, 0.35);
  AddCylinder({-5.0, -6.0, 0}, 0.5, 3.0, false, 0.45);
  AddCylinder({8.0, -2.0, 0}, 0.3, 2.5, false, 0.5);
}

// Facade blocks of 6-14 m along each side with setbacks of 0-1.5 m and heights of 6-15 m, parked
// cars, poles and trees in irregular (seeded) places: straight, but not repetitive.
void Scene::AddStreet() {
  AddGround(200, 0.35);
  std::mt19937_64 rng(20261130);
  std::uniform_real_distribution<double> unit(0, 1);
  for (const double side : {-1.0, 1.0}) {
    for (double x = -20; x < 120;) {
      const double length = 6 + 8 * unit(rng), setback = 1.5 * unit(rng);
      const double y = side * (8 + setback), height = 6 + 9 * unit(rng);
      AddBox({x, std::min(y, y + side * 6), 0},
             {x + length, std::max(y, y + side * 6), height},
             false,
             0.4 + 0.25 * unit(rng));
      x += length;
    }
    for (double x = -15; x < 115; x += 7 + 10 * unit(rng)) {  // parked cars
      const double y = side * 5.6;
      AddBox({x, y - 0.9, 0}, {x + 4.3, y + 0.9, 1.5}, false, 0.3 + 0.4 * unit(rng));
    }
    for (double x = -12; x < 115; x += 9 + 14 * unit(rng)) {  // poles and trees
      if (unit(rng) < 0.5) {
        AddCylinder({x, side * 6.8, 0}, 0.08, 5.0, false, 0.5);
      } else {
        AddCylinder({x, side * 7.0, 0}, 0.2, 3.0, false, 0.35);
        AddBox({x - 1.5, side * 7.0 - 1.5, 3.0}, {x + 1.5, side * 7.0 + 1.5, 5.5}, false, 0.3);
      }
    }
  }
  // Cars driving: one ahead in our lane, one oncoming.
  for (const auto& [start, speed] : {std::pair{Eigen::Vector3d(14, -1.8, 0.75), 6.0},
                                     std::pair{Eigen::Vector3d(90, 1.8, 0.75), -9.0}}) {
    AddBox(start - Eigen::Vector3d(2.2, 0.9, 0.75),
           start + Eigen::Vector3d(2.2, 0.9, 0.75),
           false,
           0.5);
    movers_.push_back({primitives_.size() - 1, start, Eigen::Vector3d(speed, 0, 0)});
  }
}

Scene Scene::MovedTo(double time_s) const {
  Scene moved = *this;
  for (const Mover& m : movers_) {
    moved.primitives_[m.primitive].center = m.center_at_zero + time_s * m.velocity;
    moved.frames_[m.primitive] = FrameOf(moved.primitives_[m.primitive]);
  }
  moved.Index();
  return moved;
}

bool Scene::Intersect(const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& unit_direction,
                      double max_t,
                      RayHit* hit) const {
  hit->t = max_t;
  hit->primitive = -1;
  // The closest hit; of hits at the same distance, the first primitive's.
  const auto test = [&](int i) {
    const Primitive& p = primitives_[i];
    double t;
    Eigen::Vector3d normal;
    bool ok = false;
    switch (p.type) {
      case Primitive::Type::kBox:
        ok = IntersectBox(p, frames_[i].rotation, origin, unit_direction, &t, &normal);
        break;
      case Primitive::Type::kCylinder:
        ok = IntersectCylinder(p, origin, unit_direction, &t, &normal);
        break;
      case Primitive::Type::kGround:
        ok = IntersectGround(p, origin, unit_direction, &t, &normal);
        break;
    }
    if (ok && (t < hit->t || (t == hit->t && i < hit->primitive))) {
      hit->t = t;
      hit->normal = normal;
      hit->primitive = i;
    }
  };
  for (const int i : unbounded_) test(i);
  hierarchy_.Traverse(
      origin, unit_direction, [&] { return hit->t; }, [&](int item) { test(bounded_[item]); });
  return hit->primitive >= 0;
}

double Scene::Albedo(const Eigen::Vector3d& point, int primitive) const {
  const Primitive& p = primitives_.at(primitive);
  // Concrete-like: fBm over 6 octaves from 32 cm down to 1 cm, plus dark pores of ~1-2 cm.
  static constexpr double kScales[] = {0.32, 0.16, 0.08, 0.04, 0.02, 0.01};
  static constexpr double kAmplitudes[] = {0.25, 0.25, 0.3, 0.35, 0.35, 0.25};
  double fbm = 0;
  for (int o = 0; o < 6; ++o) {
    fbm += kAmplitudes[o] * (ValueNoise(point / kScales[o], 17 + o) - 0.5);
  }
  const double pores = SmoothStep(0.72, 0.8, ValueNoise(point / 0.015, 101));
  const double albedo = p.albedo * (1 + p.texture_contrast * 2 * fbm) * (1 - 0.55 * pores);
  return std::clamp(albedo, 0.03, 1.0);
}

double Scene::Shade(const Eigen::Vector3d& point,
                    const Eigen::Vector3d& normal,
                    int primitive) const {
  const double diffuse = std::max(0.0, normal.dot(sun_direction_));
  return std::clamp(255.0 * Albedo(point, primitive) * (0.45 + 0.6 * diffuse), 0.0, 255.0);
}

bool Scene::InsideObject(const Eigen::Vector3d& point, double tolerance) const {
  for (const Primitive& p : primitives_) {
    if (!p.is_object) continue;
    if (p.type == Primitive::Type::kBox) {
      const Eigen::Vector3d local = RotZ(p.yaw).transpose() * (point - p.center);
      if ((local.cwiseAbs() - p.half_size).maxCoeff() <= tolerance) return true;
    } else if (p.type == Primitive::Type::kCylinder) {
      const Eigen::Vector3d d = point - p.center;
      if (d.head<2>().norm() <= p.half_size.x() + tolerance &&
          std::abs(d.z()) <= p.half_size.z() + tolerance) {
        return true;
      }
    }
  }
  return false;
}

namespace {

using SurfaceSampleSink =
    std::function<void(const Eigen::Vector3d& point, const Eigen::Vector3d& normal)>;

// Samples `spacing` apart on the six faces of box `p`, each with its outward normal.
void SampleBoxSurface(const Primitive& p, double spacing, const SurfaceSampleSink& keep) {
  const Eigen::Matrix3d R = RotZ(p.yaw);
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = std::max(1, static_cast<int>(std::ceil(2 * p.half_size[u] / spacing)));
    const int nv = std::max(1, static_cast<int>(std::ceil(2 * p.half_size[v] / spacing)));
    for (const double side : {-1.0, 1.0}) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = side;
      for (int a = 0; a < nu; ++a) {
        for (int b = 0; b < nv; ++b) {
          Eigen::Vector3d local;
          local[axis] = side * p.half_size[axis];
          local[u] = -p.half_size[u] + (a + 0.5) * 2 * p.half_size[u] / nu;
          local[v] = -p.half_size[v] + (b + 0.5) * 2 * p.half_size[v] / nv;
          keep(p.center + R * local, R * n);
        }
      }
    }
  }
}

// Samples `spacing` apart on the mantle and both caps of cylinder `p`.
void SampleCylinderSurface(const Primitive& p, double spacing, const SurfaceSampleSink& keep) {
  const double r = p.half_size.x(), h = p.half_size.z();
  const int n_theta = static_cast<int>(std::ceil(2 * M_PI * r / spacing));
  const int n_z = static_cast<int>(std::ceil(2 * h / spacing));
  for (int a = 0; a < n_theta; ++a) {
    const double theta = 2 * M_PI * (a + 0.5) / n_theta;
    const Eigen::Vector3d n(std::cos(theta), std::sin(theta), 0);
    for (int b = 0; b < n_z; ++b) {
      keep(p.center + r * n + Eigen::Vector3d(0, 0, -h + (b + 0.5) * 2 * h / n_z), n);
    }
  }
  const int n_cap = static_cast<int>(std::ceil(2 * r / spacing));
  for (const double side : {-1.0, 1.0}) {
    for (int a = 0; a < n_cap; ++a) {
      for (int b = 0; b < n_cap; ++b) {
        const Eigen::Vector2d xy(-r + (a + 0.5) * 2 * r / n_cap, -r + (b + 0.5) * 2 * r / n_cap);
        if (xy.norm() > r) continue;
        keep(p.center + Eigen::Vector3d(xy.x(), xy.y(), side * h), Eigen::Vector3d(0, 0, side));
      }
    }
  }
}

}  // namespace

PointCloud Scene::SampleObjectSurface(double spacing) const {
  PointCloud cloud;
  for (size_t i = 0; i < primitives_.size(); ++i) {
    const Primitive& p = primitives_[i];
    if (!p.is_object) continue;
    // Samples resting on the ground, or on or inside another object primitive (hidden faces of a
    // union), are dropped.
    const auto keep = [&](const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
      if (point.z() < 1e-4) return;
      for (size_t j = 0; j < primitives_.size(); ++j) {
        if (j == i || !primitives_[j].is_object) continue;
        Scene single;
        single.primitives_ = {primitives_[j]};
        single.frames_ = {frames_[j]};
        if (single.InsideObject(point, 1e-7)) return;
      }
      cloud.points.push_back(point);
      cloud.normals.push_back(normal);
    };
    if (p.type == Primitive::Type::kBox) SampleBoxSurface(p, spacing, keep);
    if (p.type == Primitive::Type::kCylinder) SampleCylinderSurface(p, spacing, keep);
  }
  return cloud;
}

}  // namespace sim
}  // namespace colmap_lidar
