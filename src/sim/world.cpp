// World: primitive storage, hit completion (normal, uv) and BVH traversal. The BVH build is in world_bvh.cpp.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "sim/world.hpp"
#include "sim/world_impl.hpp"

namespace drover::sim {
namespace {

using detail::kInf;
using detail::Primitive;
using detail::PrimKind;

std::string vecString(const Eigen::Vector3d& v) {
  return "(" + std::to_string(v.x()) + ", " + std::to_string(v.y()) + ", " + std::to_string(v.z()) + ")";
}

void checkMaterial(const Material& m) {
  if (!(m.scale > 0.0f) || !std::isfinite(m.scale))
    throw std::invalid_argument("World: material scale must be > 0, got " + std::to_string(m.scale));
  if (!(m.reflectivity >= 0.0f && m.reflectivity <= 1.0f))
    throw std::invalid_argument("World: material reflectivity must be in [0, 1], got " +
                                std::to_string(m.reflectivity));
}

void checkRotation(const Eigen::Matrix3d& R, const char* what) {
  if (!R.allFinite() || !(R.transpose() * R).isIdentity(1e-6) || R.determinant() < 0.0)
    throw std::invalid_argument(std::string("World: ") + what + " pose rotation is not a rotation matrix");
}

// Ray state for float slab tests against BVH node boxes: per axis, which bound is entered first (by the sign of
// the direction), so the test needs no min/max per axis.
struct FloatRay {
  float o[3];
  float inv[3];
  int near[3], far[3];  // index into BvhNode::bounds
  explicit FloatRay(const Ray& ray) {
    for (int i = 0; i < 3; ++i) {
      o[i] = static_cast<float>(ray.origin[i]);
      const double d = ray.direction[i];
      // A zero component gets a huge finite inverse so (bound - o) * inv never forms 0 * inf = NaN.
      inv[i] = d == 0.0 ? 1e30f : static_cast<float>(1.0 / d);
      near[i] = inv[i] >= 0.0f ? i : 3 + i;
      far[i] = inv[i] >= 0.0f ? 3 + i : i;
    }
  }
  // Entry distance into the node's box if the ray overlaps it within [0, t_max], else +inf.
  float enter(const detail::BvhNode& n, float t_max) const {
    const float tx0 = (n.bounds[near[0]] - o[0]) * inv[0], tx1 = (n.bounds[far[0]] - o[0]) * inv[0];
    const float ty0 = (n.bounds[near[1]] - o[1]) * inv[1], ty1 = (n.bounds[far[1]] - o[1]) * inv[1];
    const float tz0 = (n.bounds[near[2]] - o[2]) * inv[2], tz1 = (n.bounds[far[2]] - o[2]) * inv[2];
    const float t_near = std::max(std::max(tx0, ty0), std::max(tz0, 0.0f));
    const float t_far = std::min(std::min(tx1, ty1), std::min(tz1, t_max));
    return t_near <= t_far ? t_near : std::numeric_limits<float>::infinity();
  }
};

}  // namespace

namespace detail {

void completeHit(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t, Hit& hit) {
  hit.distance = t;
  hit.point = o + t * d;
  switch (p.kind) {
    case PrimKind::kBox: {
      const Eigen::Vector3d ql = p.R_world_local.transpose() * (hit.point - p.center);
      const Eigen::Vector3d dl = p.R_world_local.transpose() * d;
      // The face hit is the one whose slab boundary the point lies on (largest relative coordinate).
      int axis = 0;
      double best = -1.0;
      for (int i = 0; i < 3; ++i) {
        const double rel = std::abs(ql[i]) / p.half[i];
        if (rel > best) best = rel, axis = i;
      }
      Eigen::Vector3d nl = Eigen::Vector3d::Zero();
      nl[axis] = dl[axis] > 0.0 ? -1.0 : 1.0;  // against the ray: faces the origin both from outside and inside
      hit.normal = p.R_world_local * nl;
      if (axis == 0) hit.uv = {ql.y(), ql.z()};
      else if (axis == 1) hit.uv = {ql.x(), ql.z()};
      else hit.uv = {ql.x(), ql.y()};
      break;
    }
    case PrimKind::kCylinder: {
      const Eigen::Vector3d f = hit.point - p.center;
      const double radius = p.half[0];
      const double radial = std::hypot(f.x(), f.y()) / radius;
      const double from_cap = std::min(std::abs(f.z()), std::abs(f.z() - p.half[2])) / radius;
      if (from_cap < std::abs(1.0 - radial)) {  // on a cap
        hit.normal = Eigen::Vector3d(0, 0, d.z() > 0.0 ? -1.0 : 1.0);
        hit.uv = {f.x(), f.y()};
      } else {
        hit.normal = Eigen::Vector3d(f.x(), f.y(), 0.0).normalized();
        if (hit.normal.dot(d) > 0.0) hit.normal = -hit.normal;
        hit.uv = {radius * std::atan2(f.y(), f.x()), f.z()};
      }
      break;
    }
    case PrimKind::kRectangle: {
      const Eigen::Vector3d n = p.R_world_local.col(2);
      hit.normal = n.dot(d) > 0.0 ? Eigen::Vector3d(-n) : n;
      const Eigen::Vector3d f = hit.point - p.center;
      hit.uv = {p.R_world_local.col(0).dot(f), p.R_world_local.col(1).dot(f)};
      break;
    }
  }
}

}  // namespace detail

World::Impl& World::mutableImpl() {
  if (!impl_) impl_ = std::make_shared<Impl>();
  if (impl_->built) throw std::logic_error("World: cannot add to a world after build()");
  return *impl_;
}

void World::setGround(double ground_height, const Material& material) {
  if (!std::isfinite(ground_height))
    throw std::invalid_argument("World::setGround: ground_height must be finite, got " + std::to_string(ground_height));
  checkMaterial(material);
  Impl& w = mutableImpl();
  w.has_ground = true;
  w.ground_height = ground_height;
  w.ground_material = static_cast<std::uint32_t>(w.materials.size());
  w.materials.push_back(material);
}

namespace {
std::uint32_t addPrimitive(detail::WorldData& w, Primitive p, const Material& material) {
  checkMaterial(material);
  p.material = static_cast<std::uint32_t>(w.materials.size());
  p.id = static_cast<std::uint32_t>(w.prims.size());
  w.materials.push_back(material);
  w.prims.push_back(p);
  return p.id;
}
}  // namespace

std::uint32_t World::addBox(const Box& box, const Material& material) {
  if (!(box.half_extents.array() > 0.0).all() || !box.half_extents.allFinite())
    throw std::invalid_argument("World::addBox: half_extents must be > 0, got " + vecString(box.half_extents));
  checkRotation(box.T_world_box.linear(), "box");
  Primitive p;
  p.kind = PrimKind::kBox;
  p.R_world_local = box.T_world_box.linear();
  p.center = box.T_world_box.translation();
  p.half = box.half_extents;
  return addPrimitive(mutableImpl(), p, material);
}

std::uint32_t World::addCylinder(const Cylinder& c, const Material& material) {
  if (!(c.radius > 0.0) || !std::isfinite(c.radius))
    throw std::invalid_argument("World::addCylinder: radius must be > 0, got " + std::to_string(c.radius));
  if (!(c.height > 0.0) || !std::isfinite(c.height))
    throw std::invalid_argument("World::addCylinder: height must be > 0, got " + std::to_string(c.height));
  if (!c.base_center.allFinite())
    throw std::invalid_argument("World::addCylinder: base_center not finite: " + vecString(c.base_center));
  Primitive p;
  p.kind = PrimKind::kCylinder;
  p.center = c.base_center;
  p.half = Eigen::Vector3d(c.radius, c.radius * c.radius, c.height);
  return addPrimitive(mutableImpl(), p, material);
}

std::uint32_t World::addRectangle(const Rectangle& rect, const Material& material) {
  if (!(rect.half_size.array() > 0.0).all() || !rect.half_size.allFinite())
    throw std::invalid_argument("World::addRectangle: half_size must be > 0, got (" +
                                std::to_string(rect.half_size.x()) + ", " + std::to_string(rect.half_size.y()) + ")");
  checkRotation(rect.T_world_rect.linear(), "rectangle");
  Primitive p;
  p.kind = PrimKind::kRectangle;
  p.R_world_local = rect.T_world_rect.linear();
  p.center = rect.T_world_rect.translation();
  p.half = Eigen::Vector3d(rect.half_size.x(), rect.half_size.y(), 0.0);
  return addPrimitive(mutableImpl(), p, material);
}

void World::addIndoorRegion(const IndoorRegion& region) {
  if (!(region.min_corner.array() <= region.max_corner.array()).all())
    throw std::invalid_argument("World::addIndoorRegion: min_corner " + vecString(region.min_corner) +
                                " exceeds max_corner " + vecString(region.max_corner));
  mutableImpl().indoor.push_back(region);
}

void World::build() {
  Impl& w = mutableImpl();
  w.nodes = detail::buildBvh(w.prims);
  w.built = true;
}

std::size_t World::primitiveCount() const { return impl_ ? impl_->prims.size() : 0; }

bool World::isIndoor(const Eigen::Vector3d& p) const {
  if (!impl_) return false;
  return std::any_of(impl_->indoor.begin(), impl_->indoor.end(), [&](const IndoorRegion& r) {
    return (p.array() >= r.min_corner.array()).all() && (p.array() <= r.max_corner.array()).all();
  });
}

namespace {

// The ground plane z = h: a hit in (t_min, t_max) or kInf.
double intersectGround(const detail::WorldData& w, const Ray& ray, double t_min, double t_max) {
  if (!w.has_ground || ray.direction.z() == 0.0) return kInf;
  const double t = (w.ground_height - ray.origin.z()) / ray.direction.z();
  return t > t_min && t < t_max ? t : kInf;
}

Hit groundHit(const detail::WorldData& w, const Ray& ray, double t) {
  Hit hit;
  hit.distance = t;
  hit.point = ray.origin + t * ray.direction;
  hit.point.z() = w.ground_height;
  hit.normal = Eigen::Vector3d(0, 0, ray.direction.z() > 0.0 ? -1.0 : 1.0);
  hit.uv = hit.point.head<2>();
  hit.primitive = World::kGroundPrimitive;
  hit.material = &w.materials[w.ground_material];
  return hit;
}

std::optional<Hit> finish(const detail::WorldData& w, const Ray& ray, double ground_t, double best,
                          const Primitive* best_prim) {
  if (best_prim == nullptr) {
    if (ground_t == kInf) return std::nullopt;
    return groundHit(w, ray, ground_t);
  }
  Hit hit;
  detail::completeHit(*best_prim, ray.origin, ray.direction, best, hit);
  hit.primitive = best_prim->id;
  hit.material = &w.materials[best_prim->material];
  return hit;
}

template <typename ImplPtr>
const detail::WorldData& builtImpl(const ImplPtr& impl) {
  if (!impl || !impl->built) throw std::logic_error("World::intersect called before build()");
  return *impl;
}

}  // namespace

std::optional<Hit> World::intersect(const Ray& ray, double t_min, double t_max) const {
  const detail::WorldData& w = builtImpl(impl_);
  const double ground_t = intersectGround(w, ray, t_min, t_max);
  double best = std::min(ground_t, t_max);  // the ground bounds the search for everything else
  const Primitive* best_prim = nullptr;
  if (w.nodes.empty()) return finish(w, ray, ground_t, best, best_prim);

  const FloatRay fr(ray);
  // Float distances are compared against a slightly enlarged best so rounding never culls a closer hit (the node
  // boxes are padded too; see world_bvh.cpp).
  const auto cull_bound = [&] { return static_cast<float>(best) * 1.000001f + 1e-4f; };
  struct Entry {
    std::uint32_t node;
    float t;
  };
  Entry stack[128];  // >= tree depth: SAH depth is capped at 48, then median splits halve
  int top = 0;
  if (fr.enter(w.nodes[0], cull_bound()) == std::numeric_limits<float>::infinity()) {
    return finish(w, ray, ground_t, best, best_prim);
  }
  stack[top++] = {0, 0.0f};
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.t > cull_bound()) continue;
    const detail::BvhNode* n = &w.nodes[e.node];
    while (n->count == 0) {  // inner: visit the nearer child now, push the farther one
      const std::uint32_t l = static_cast<std::uint32_t>(n - w.nodes.data()) + 1, r = n->index;
      const float bound = cull_bound();
      float tl = fr.enter(w.nodes[l], bound), tr = fr.enter(w.nodes[r], bound);
      std::uint32_t near = l, far = r;
      if (tr < tl) std::swap(tl, tr), std::swap(near, far);
      if (tl == std::numeric_limits<float>::infinity()) {
        n = nullptr;
        break;
      }
      if (tr != std::numeric_limits<float>::infinity()) stack[top++] = {far, tr};
      n = &w.nodes[near];
    }
    if (n == nullptr) continue;
    for (std::uint32_t i = n->index; i < n->index + n->count; ++i) {
      const double t = detail::intersectPrimitive(w.prims[i], ray.origin, ray.direction, t_min, best);
      if (t < best) best = t, best_prim = &w.prims[i];
    }
  }
  return finish(w, ray, ground_t, best, best_prim);
}

std::optional<Hit> World::intersectBruteForce(const Ray& ray, double t_min, double t_max) const {
  const detail::WorldData& w = builtImpl(impl_);
  const double ground_t = intersectGround(w, ray, t_min, t_max);
  double best = std::min(ground_t, t_max);
  const Primitive* best_prim = nullptr;
  for (const Primitive& p : w.prims) {
    const double t = detail::intersectPrimitive(p, ray.origin, ray.direction, t_min, best);
    if (t < best) best = t, best_prim = &p;
  }
  return finish(w, ray, ground_t, best, best_prim);
}

}  // namespace drover::sim
