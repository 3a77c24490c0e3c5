// World-building helpers and the scenario lighting.
#include "sim/scenario_world.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

namespace drover::sim::detail {
namespace {

float smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return static_cast<float>(x * x * (3.0 - 2.0 * x));
}

}  // namespace

Material makeMaterial(Texture texture, const Eigen::Vector3f& albedo, float reflectivity, float scale,
                      std::uint32_t seed) {
  Material m;
  m.texture = texture;
  m.albedo = albedo;
  m.reflectivity = reflectivity;
  m.scale = scale;
  m.seed = seed;
  return m;
}

Rectangle verticalRect(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double z1) {
  const Eigen::Vector2d d = b - a;
  const Eigen::Vector3d x(d.x() / d.norm(), d.y() / d.norm(), 0.0), y(0.0, 0.0, 1.0);
  Rectangle r;
  r.T_world_rect.linear().col(0) = x;
  r.T_world_rect.linear().col(1) = y;
  r.T_world_rect.linear().col(2) = x.cross(y);
  const Eigen::Vector2d mid = 0.5 * (a + b);
  r.T_world_rect.translation() = Eigen::Vector3d(mid.x(), mid.y(), 0.5 * (z0 + z1));
  r.half_size = Eigen::Vector2d(0.5 * d.norm(), 0.5 * (z1 - z0));
  return r;
}

Box yawBox(const Eigen::Vector3d& base, const Eigen::Vector3d& half, double yaw) {
  Box b;
  b.T_world_box = Eigen::Translation3d(base + Eigen::Vector3d(0.0, 0.0, half.z())) *
                  Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
  b.half_extents = half;
  return b;
}

Footprint footprintOf(const Box& box) {
  const Eigen::Matrix3d& R = box.T_world_box.linear();
  Footprint f;
  f.center = box.T_world_box.translation().head<2>();
  f.half = box.half_extents.head<2>();
  f.yaw = std::atan2(R(1, 0), R(0, 0));
  return f;
}

Footprint footprintOf(const Rectangle& r) {
  const Eigen::Matrix3d& R = r.T_world_rect.linear();
  Footprint f;
  f.center = r.T_world_rect.translation().head<2>();
  f.half = Eigen::Vector2d(r.half_size.x(), 0.05);
  f.yaw = std::atan2(R(1, 0), R(0, 0));
  return f;
}

// ---- lighting -----------------------------------------------------------------------------------------------

float LightingPlan::temporal(Time t) const {
  for (const LightingEvent& e : events) {
    if (t < e.start || t > e.end) continue;
    const double span = toSeconds(e.end - e.start);
    const double u = toSeconds(t - e.start) / span;
    const auto towards_dark = [&](double s) { return static_cast<float>(std::pow(dark, smoothstep(s))); };
    if (u < 0.2) return towards_dark(u / 0.2);                  // ramp down: 1 -> dark geometrically
    if (u < 0.45) return dark;                                  // dark stretch
    if (u < 0.6) return towards_dark(1.0 - (u - 0.45) / 0.15);  // ramp back up
    const double tf = toSeconds(t - e.start) - 0.6 * span;                     // flicker from 1
    return 1.0f - flicker_depth * static_cast<float>(0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * flicker_hz * tf)));
  }
  return 1.0f;
}

float LightingPlan::at(Time t, const Eigen::Vector3d& p) const {
  const bool inside = std::any_of(indoor_regions.begin(), indoor_regions.end(), [&](const IndoorRegion& r) {
    return (p.array() >= r.min_corner.array()).all() && (p.array() <= r.max_corner.array()).all();
  });
  return (inside ? indoor : outdoor) * temporal(t);
}

Illumination makeIllumination(const LightingPlan& plan) {
  auto shared = std::make_shared<const LightingPlan>(plan);
  return [shared](Time t, const Eigen::Vector3d& p) { return shared->at(t, p); };
}

// ---- world builder ------------------------------------------------------------------------------------------

void WorldBuilder::decor(const Box& b, const Material& m, double clearance) {
  Item item;
  item.boxes = {b};
  item.box_m = {m};
  item.footprints = {footprintOf(b)};
  item.clearance = clearance;
  items_.push_back(std::move(item));
}

void WorldBuilder::decor(const Rectangle& r, const Material& m, double clearance) {
  Item item;
  item.rects = {r};
  item.rect_m = {m};
  item.footprints = {footprintOf(r)};
  item.clearance = clearance;
  items_.push_back(std::move(item));
}

void WorldBuilder::decor(const Cylinder& c, const Material& m, double clearance) {
  Item item;
  item.cylinders = {c};
  item.cyl_m = {m};
  Footprint f;
  f.center = c.base_center.head<2>();
  f.radius = c.radius;
  item.footprints = {f};
  item.clearance = clearance;
  items_.push_back(std::move(item));
}

void WorldBuilder::tree(const Eigen::Vector3d& base, double height, double crown, std::uint32_t seed,
                        double clearance) {
  Item item;
  Cylinder trunk;
  trunk.base_center = base;
  trunk.radius = 0.15 + 0.03 * crown;
  trunk.height = 0.6 * height;
  item.cylinders = {trunk};
  item.cyl_m = {makeMaterial(Texture::kBark, {0.35f, 0.25f, 0.15f}, 0.4f, 0.3f, seed)};
  const Box foliage =
      yawBox(base + Eigen::Vector3d(0.0, 0.0, 0.45 * height), Eigen::Vector3d(crown, crown, 0.3 * height), 0.37 * seed);
  item.boxes = {foliage};
  item.box_m = {makeMaterial(Texture::kFoliage, {0.2f, 0.45f, 0.15f}, 0.3f, 0.4f, seed)};
  Footprint f;
  f.center = base.head<2>();
  f.radius = crown * std::numbers::sqrt2;  // the crown turned any way
  item.footprints = {f};
  item.clearance = clearance;
  items_.push_back(std::move(item));
}

void WorldBuilder::indoor(const IndoorRegion& region) {
  world_.addIndoorRegion(region);
  indoor_.push_back(region);
}

World WorldBuilder::finish(const PathIndex& path) {
  for (const Item& item : items_) {
    const bool clear = std::all_of(item.footprints.begin(), item.footprints.end(), [&](const Footprint& f) {
      if (path.distance(f, item.clearance) < item.clearance) return false;
      return std::none_of(keep_out_.begin(), keep_out_.end(),
                          [&](const Footprint& zone) { return footprintsOverlap(zone, f); });
    });
    if (!clear) continue;
    for (std::size_t i = 0; i < item.boxes.size(); ++i) world_.addBox(item.boxes[i], item.box_m[i]);
    for (std::size_t i = 0; i < item.rects.size(); ++i) world_.addRectangle(item.rects[i], item.rect_m[i]);
    for (std::size_t i = 0; i < item.cylinders.size(); ++i) world_.addCylinder(item.cylinders[i], item.cyl_m[i]);
  }
  items_.clear();
  world_.build();
  return world_;
}

}  // namespace drover::sim::detail
