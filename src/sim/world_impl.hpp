#pragma once
// Private to world*.cpp: the World's storage, the BVH layout and the per-primitive ray tests.
// The ray tests run in double (ranges must be exact to ~1e-9 m for the lidar tests); BVH boxes are float, padded
// outward so float rounding can never cull a true hit.
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <vector>

#include "sim/world.hpp"

namespace drover::sim::detail {

enum class PrimKind : std::uint8_t { kBox, kCylinder, kRectangle };

// One primitive as the ray tests need it.
//   box:       R_world_local, center = box centre, half = half extents
//   cylinder:  center = centre of the bottom cap, half = (radius, radius^2, height)
//   rectangle: R_world_local, center = rectangle centre, half = (hx, hy, 0); normal = local +z
struct Primitive {
  Eigen::Matrix3d R_world_local = Eigen::Matrix3d::Identity();
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  PrimKind kind = PrimKind::kBox;
  std::uint32_t material = 0;  // index into World::Impl::materials
  std::uint32_t id = 0;        // the index add*() returned
};

// A flattened BVH node (32 bytes). Inner nodes: left child = this index + 1, right child = `index`.
// Leaves: primitives [index, index + count) of Impl::prims (stored in BVH order).
struct BvhNode {
  float bounds[6];  // min x, y, z then max x, y, z [m], world
  std::uint32_t index;
  std::uint32_t count;  // 0 for inner nodes
};

struct Aabb {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  void grow(const Aabb& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  void grow(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  double halfArea() const {
    const Eigen::Vector3d e = (hi - lo).cwiseMax(0.0);
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  }
};

Aabb primitiveBounds(const Primitive& p);
// Builds the BVH over `prims` (reordered into leaf order) and returns the flattened nodes.
std::vector<BvhNode> buildBvh(std::vector<Primitive>& prims);

constexpr double kInf = std::numeric_limits<double>::infinity();

// Ray tests: the distance of the nearest hit in (t_min, t_max), or kInf. Origin o, unit direction d, world frame.
inline double intersectBox(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                           double t_max) {
  const Eigen::Vector3d ol = p.R_world_local.transpose() * (o - p.center);
  const Eigen::Vector3d dl = p.R_world_local.transpose() * d;
  double t_near = -kInf, t_far = kInf;
  for (int i = 0; i < 3; ++i) {
    if (dl[i] == 0.0) {
      if (std::abs(ol[i]) > p.half[i]) return kInf;  // parallel to this slab and outside it
      continue;
    }
    const double inv = 1.0 / dl[i];
    double t0 = (-p.half[i] - ol[i]) * inv, t1 = (p.half[i] - ol[i]) * inv;
    if (t0 > t1) std::swap(t0, t1);
    t_near = std::max(t_near, t0);
    t_far = std::min(t_far, t1);
  }
  if (t_near > t_far) return kInf;
  if (t_near > t_min && t_near < t_max) return t_near;  // entering from outside
  if (t_far > t_min && t_far < t_max) return t_far;     // leaving from inside
  return kInf;
}

inline double intersectCylinder(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                                double t_max) {
  const double r2 = p.half[1], z0 = p.center.z(), z1 = p.center.z() + p.half[2];
  const double fx = o.x() - p.center.x(), fy = o.y() - p.center.y();
  double best = kInf;
  const auto consider = [&](double t) {
    if (t > t_min && t < t_max && t < best) best = t;
  };
  // Side: |f + t d_xy|^2 = r^2 with z in [z0, z1].
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a > 0.0) {
    const double b = fx * d.x() + fy * d.y();  // half of the linear coefficient
    const double c = fx * fx + fy * fy - r2;
    const double disc = b * b - a * c;
    if (disc >= 0.0) {
      const double s = std::sqrt(disc);
      for (const double t : {(-b - s) / a, (-b + s) / a}) {
        const double z = o.z() + t * d.z();
        if (z >= z0 && z <= z1) consider(t);
      }
    }
  }
  // Caps: planes z = z0 and z = z1 within the radius.
  if (d.z() != 0.0) {
    for (const double zc : {z0, z1}) {
      const double t = (zc - o.z()) / d.z();
      const double x = fx + t * d.x(), y = fy + t * d.y();
      if (x * x + y * y <= r2) consider(t);
    }
  }
  return best;
}

inline double intersectRectangle(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                 double t_min, double t_max) {
  const Eigen::Vector3d n = p.R_world_local.col(2);
  const double dn = n.dot(d);
  if (dn == 0.0) return kInf;  // parallel (grazing): no hit on a zero-thickness surface
  const Eigen::Vector3d f = o - p.center;
  const double t = -n.dot(f) / dn;
  if (!(t > t_min && t < t_max)) return kInf;
  const Eigen::Vector3d q = f + t * d;
  if (std::abs(p.R_world_local.col(0).dot(q)) > p.half[0] || std::abs(p.R_world_local.col(1).dot(q)) > p.half[1])
    return kInf;
  return t;
}

inline double intersectPrimitive(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                 double t_min, double t_max) {
  switch (p.kind) {
    case PrimKind::kBox: return intersectBox(p, o, d, t_min, t_max);
    case PrimKind::kCylinder: return intersectCylinder(p, o, d, t_min, t_max);
    case PrimKind::kRectangle: return intersectRectangle(p, o, d, t_min, t_max);
  }
  return kInf;
}

// Normal (facing the ray origin) and uv of a hit at distance t on p.
void completeHit(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t, Hit& hit);

// The World's contents (World::Impl derives from it so free helpers can name it).
struct WorldData {
  bool has_ground = false;
  double ground_height = 0;
  std::uint32_t ground_material = 0;
  std::deque<Material> materials;          // deque: Hit::material pointers stay valid while adding
  std::vector<detail::Primitive> prims;    // BVH leaf order after build()
  std::vector<detail::BvhNode> nodes;
  std::vector<IndoorRegion> indoor;
  bool built = false;
};

}  // namespace drover::sim::detail

namespace drover::sim {
struct World::Impl : detail::WorldData {};
}  // namespace drover::sim
