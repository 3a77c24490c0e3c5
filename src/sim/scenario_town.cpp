// The procedural town of kitti05-replay: walking the path every 4 m, asphalt under it, building facades 6.5-9.5 m
// to both sides, street trees and parked cars; nothing placed within clearance of ANY part of the path (the path
// crosses itself and revisits streets), nothing placed twice where the path comes back.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>

#include "sim/random.hpp"
#include "sim/scenario_internal.hpp"

namespace drover::sim::detail {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using G = CourseGeometry;

enum Category : std::uint64_t { kFacade = 11, kTree = 12, kCar = 13 };

// Footprints already placed, on a coarse grid, for "does this overlap anything" queries.
class Placed {
 public:
  bool overlaps(const Footprint& f) const {
    const auto [ix, iy] = cellOf(f.center);
    for (std::int64_t dx = -2; dx <= 2; ++dx) {
      for (std::int64_t dy = -2; dy <= 2; ++dy) {
        const auto it = grid_.find(key(ix + dx, iy + dy));
        if (it == grid_.end()) continue;
        for (const Footprint& g : it->second)
          if (footprintsOverlap(g, f)) return true;
      }
    }
    return false;
  }
  void add(const Footprint& f) {
    const auto [ix, iy] = cellOf(f.center);
    grid_[key(ix, iy)].push_back(f);
  }

 private:
  static constexpr double kCell = 8.0;  // [m]; footprints are smaller than 2 cells
  static std::pair<std::int64_t, std::int64_t> cellOf(const Vector2d& p) {
    return {static_cast<std::int64_t>(std::floor(p.x() / kCell)), static_cast<std::int64_t>(std::floor(p.y() / kCell))};
  }
  static std::int64_t key(std::int64_t ix, std::int64_t iy) { return ix * 1'000'003LL + iy; }
  std::unordered_map<std::int64_t, std::vector<Footprint>> grid_;
};

struct Station {
  Vector2d p;
  double yaw, z_road;
  Eigen::Matrix3d R;  // body orientation
};

Eigen::Matrix3d eulerZyx(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Vector3d::UnitX()))
      .toRotationMatrix();
}

class TownBuilder {
 public:
  TownBuilder(const std::vector<PathSample>& samples, std::uint64_t seed) : seed_(seed), path_(densePath(samples)) {}

  double u(std::uint64_t category, std::uint64_t station, std::uint64_t side, std::uint64_t k) const {
    return uniform01(hashKeys(seed_, static_cast<std::uint64_t>(Stream::kScenario), category, station, side, k));
  }

  void road(const Station& s) {
    Footprint f{s.p, Vector2d::Zero(), 0.0, 1.0};
    if (strips_.overlaps(f)) return;  // a strip within 2 m: this stretch of street has its asphalt already
    strips_.add(f);
    Rectangle r;
    r.T_world_rect.linear() = s.R;
    r.T_world_rect.translation() = Vector3d(s.p.x(), s.p.y(), s.z_road);
    r.half_size = Vector2d(2.6, 10.0);
    world_.addRectangle(r, makeMaterial(Texture::kAsphalt, {0.25f, 0.25f, 0.27f}, 0.25f, 0.3f, 1));
  }

  void facade(const Station& s, std::uint64_t k, int side) {
    const auto r = [&](std::uint64_t i) { return u(kFacade, k, static_cast<std::uint64_t>(side + 1), i); };
    if (r(0) < 0.15) return;  // a gap between buildings
    // About one station pair (8 m) long, so neighbours nearly touch along a straight street.
    const double front = 6.5 + 3.0 * r(1), length = 7.0 + 0.9 * r(2), depth = 6.0 + 4.0 * r(3);
    const double height = 6.0 + 12.0 * r(4);
    const Vector2d left(-std::sin(s.yaw), std::cos(s.yaw));
    const Vector2d c = s.p + side * (front + depth / 2) * left;
    const Box b =
        yawBox(Vector3d(c.x(), c.y(), s.z_road - 1.0), Vector3d(length / 2, depth / 2, height / 2 + 0.5), s.yaw);
    const bool brick = r(5) < 0.5;
    const float shade = static_cast<float>(0.45 + 0.4 * r(6));
    Footprint touching = footprintOf(b);  // may touch its neighbours
    touching.half.array() -= 0.3;
    place(b, touching, 5.0,
          makeMaterial(brick ? Texture::kBrick : Texture::kConcrete,
                       brick ? Eigen::Vector3f(shade, 0.5f * shade, 0.4f * shade) : Eigen::Vector3f::Constant(shade),
                       0.5f, brick ? 0.25f : 0.6f, static_cast<std::uint32_t>(k * 2 + (side > 0))));
  }

  void tree(const Station& s, std::uint64_t k, int side) {
    const auto r = [&](std::uint64_t i) { return u(kTree, k, static_cast<std::uint64_t>(side + 1), i); };
    if (r(0) < 0.4) return;
    const double lateral = 5.0 + 0.8 * r(1), crown = 1.0 + 0.5 * r(2), height = 5.0 + 3.0 * r(3);
    const Vector2d p = s.p + side * lateral * Vector2d(-std::sin(s.yaw), std::cos(s.yaw));
    const Footprint f{p, Vector2d::Zero(), 0.0, crown * std::numbers::sqrt2};
    if (!clear(f, 2.5)) return;
    placed_.add(f);
    const auto seed = static_cast<std::uint32_t>(1000 + k * 2 + (side > 0));
    Cylinder trunk;
    trunk.base_center = Vector3d(p.x(), p.y(), s.z_road - 0.5);
    trunk.radius = 0.2;
    trunk.height = 0.6 * height + 0.5;
    world_.addCylinder(trunk, makeMaterial(Texture::kBark, {0.35f, 0.25f, 0.15f}, 0.4f, 0.3f, seed));
    const Box crown_box =
        yawBox(Vector3d(p.x(), p.y(), s.z_road + 0.45 * height), Vector3d(crown, crown, 0.3 * height), 6.0 * r(4));
    world_.addBox(crown_box, makeMaterial(Texture::kFoliage, {0.2f, 0.45f, 0.15f}, 0.3f, 0.4f, seed));
  }

  void car(const Station& s, std::uint64_t k, int side) {
    const auto r = [&](std::uint64_t i) { return u(kCar, k, static_cast<std::uint64_t>(side + 1), i); };
    if (r(0) < 0.55) return;
    const Vector2d p = s.p + side * (3.6 + 0.3 * r(1)) * Vector2d(-std::sin(s.yaw), std::cos(s.yaw));
    const Box b =
        yawBox(Vector3d(p.x(), p.y(), s.z_road - 0.05), Vector3d(2.1, 0.85, 0.72), s.yaw + 0.1 * (r(2) - 0.5));
    const Eigen::Vector3f paint(static_cast<float>(r(3)), static_cast<float>(r(4)), static_cast<float>(r(5)));
    place(b, footprintOf(b), G::kTownClearance + 0.2,
          makeMaterial(Texture::kCarPaint, paint, 0.7f, 1.0f, static_cast<std::uint32_t>(2000 + k)));
  }

  // Stations exactly `spacing` m apart along the path (interpolated between samples).
  std::vector<Station> stations(const std::vector<PathSample>& samples, double spacing) const {
    std::vector<Station> out;
    double travelled = 0.0, next = 0.0;
    for (std::size_t i = 1; i < samples.size(); ++i) {
      const PathSample &a = samples[i - 1], &b = samples[i];
      const double step = (b.p_world - a.p_world).head<2>().norm();
      for (; next <= travelled + step; next += spacing) {
        const double w = step > 0.0 ? (next - travelled) / step : 0.0;
        const Eigen::Matrix3d R =
            eulerZyx(a.yaw + w * (b.yaw - a.yaw), a.pitch + w * (b.pitch - a.pitch), a.roll + w * (b.roll - a.roll));
        const Vector3d road = a.p_world + w * (b.p_world - a.p_world) - G::kKittiCameraHeight * R.col(2);
        out.push_back({road.head<2>(), a.yaw + w * (b.yaw - a.yaw), road.z(), R});
      }
      travelled += step;
    }
    return out;
  }

  World finish(double ground) {
    world_.setGround(ground, makeMaterial(Texture::kNoise, {0.4f, 0.38f, 0.33f}, 0.3f, 0.5f, 3));
    world_.build();
    return world_;
  }

 private:
  static std::vector<Vector2d> densePath(const std::vector<PathSample>& samples) {
    std::vector<Vector2d> pts;
    for (std::size_t i = 0; i + 1 < samples.size(); ++i) {
      const Vector2d a = samples[i].p_world.head<2>(), b = samples[i + 1].p_world.head<2>();
      const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.5)));
      for (int j = 0; j < n; ++j) pts.push_back(a + (b - a) * (static_cast<double>(j) / n));
    }
    pts.push_back(samples.back().p_world.head<2>());
    return pts;
  }
  bool clear(const Footprint& f, double clearance) const {
    return path_.distance(f, clearance) >= clearance && !placed_.overlaps(f);
  }
  template <typename Prim>
  void place(const Prim& prim, const Footprint& f, double clearance, const Material& m) {
    if (!clear(f, clearance)) return;
    placed_.add(f);
    world_.addBox(prim, m);
  }

  std::uint64_t seed_;
  PathIndex path_;
  Placed placed_, strips_;
  World world_;
};

}  // namespace

World buildTown(const std::vector<PathSample>& samples, std::uint64_t seed) {
  TownBuilder town(samples, seed);
  double z_min = samples.front().p_world.z();
  for (const PathSample& s : samples) z_min = std::min(z_min, s.p_world.z());
  const std::vector<Station> stations = town.stations(samples, 4.0);
  for (std::size_t k = 0; k < stations.size(); ++k) {
    town.road(stations[k]);
    for (const int side : {1, -1}) {
      if (k % 2 == 0) town.facade(stations[k], k, side);
      if (k % 3 == 0) town.tree(stations[k], k, side);
      if (k % 3 == 1) town.car(stations[k], k, side);
    }
  }
  return town.finish(z_min - G::kKittiCameraHeight - 0.5);
}

}  // namespace drover::sim::detail
