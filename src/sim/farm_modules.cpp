// Building blocks of the livestock-farm course: barn, ramp mound, jolting track, corridor, white walls, lighting
// shed, sharp turns among pens, fenced road, trees.
#include "sim/farm_modules.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace drover::sim::detail {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using G = CourseGeometry;
constexpr double kPi = std::numbers::pi;

// Decoration categories (hash keys).
enum Category : std::uint64_t { kTrees = 1, kBales = 2, kPens = 3, kFences = 4 };

Material brick(std::uint32_t seed) { return makeMaterial(Texture::kBrick, {0.55f, 0.27f, 0.2f}, 0.5f, 0.25f, seed); }
Material concrete(std::uint32_t seed) {
  return makeMaterial(Texture::kConcrete, {0.6f, 0.6f, 0.58f}, 0.5f, 0.5f, seed);
}
Material straw(std::uint32_t seed) { return makeMaterial(Texture::kStraw, {0.85f, 0.75f, 0.4f}, 0.45f, 0.08f, seed); }
Material white() { return makeMaterial(Texture::kWhite, {0.95f, 0.95f, 0.95f}, 0.8f, 1.0f, 0); }
Material metal(std::uint32_t seed) { return makeMaterial(Texture::kMetal, {0.6f, 0.62f, 0.65f}, 0.6f, 1.0f, seed); }
Material pen(std::uint32_t seed) { return makeMaterial(Texture::kPen, {0.55f, 0.45f, 0.3f}, 0.4f, 0.2f, seed); }
Material fence(std::uint32_t seed) { return makeMaterial(Texture::kFence, {0.5f, 0.4f, 0.3f}, 0.4f, 0.15f, seed); }

// A horizontal rectangle at height z, centred at (x, y) of frame f, long side along the heading.
Rectangle flatRect(const PlanarPose& f, double x, double y, double z, double hx, double hy) {
  Rectangle r;
  const Vector2d c = f.toWorld(x, y);
  r.T_world_rect = Eigen::Translation3d(c.x(), c.y(), z) * Eigen::AngleAxisd(f.heading, Vector3d::UnitZ());
  r.half_size = Vector2d(hx, hy);
  return r;
}

// The axis-aligned bounds of a frame's local rectangle [x0, x1] x [y0, y1] between heights z0 and z1.
IndoorRegion regionOf(const PlanarPose& f, double x0, double x1, double y0, double y1, double z0, double z1) {
  IndoorRegion r{Vector3d::Constant(1e9), Vector3d::Constant(-1e9)};
  for (const double x : {x0, x1}) {
    for (const double y : {y0, y1}) {
      const Vector2d p = f.toWorld(x, y);
      r.min_corner = r.min_corner.cwiseMin(Vector3d(p.x(), p.y(), z0));
      r.max_corner = r.max_corner.cwiseMax(Vector3d(p.x(), p.y(), z1));
    }
  }
  return r;
}

Footprint footprintAlong(const PlanarPose& f, double x0, double x1, double half_width) {
  Footprint fp;
  fp.center = f.toWorld(0.5 * (x0 + x1), 0.0);
  fp.half = Vector2d(0.5 * (x1 - x0), half_width);
  fp.yaw = f.heading;
  return fp;
}

// Parallel walls at +-half_width along frame x in [x0, x1], in panels of `panel` m sharing one material.
void wallsAlong(Scene& s, const PlanarPose& f, double x0, double x1, double half_width, double height, double panel,
                const Material& m) {
  const int n = std::max(1, static_cast<int>(std::round((x1 - x0) / panel)));
  for (int i = 0; i < n; ++i) {
    const double a = x0 + (x1 - x0) * i / n, b = x0 + (x1 - x0) * (i + 1) / n;
    for (const double y : {half_width, -half_width})
      s.world.structure(verticalRect(f.toWorld(a, y), f.toWorld(b, y), f.z, f.z + height), m);
  }
}

// A slab whose top face is the planar ramp from (x0, za) to (x1, zb) along frame f, half width hw. Its low end
// reaches on below the ground; its high end stops at the platform's edge (no lip above it).
Box rampSlab(const PlanarPose& f, double x0, double x1, double za, double zb, double hw) {
  constexpr double kThickness = 0.3, kTuck = 0.3;  // [m]
  const Vector2d a2 = f.toWorld(x0, 0.0), b2 = f.toWorld(x1, 0.0);
  Vector3d lo(a2.x(), a2.y(), za), hi(b2.x(), b2.y(), zb);
  if (za > zb) std::swap(lo, hi);
  lo -= kTuck * (hi - lo).normalized();
  const double theta = -std::atan2(zb - za, x1 - x0);
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(f.heading, Vector3d::UnitZ()) * Eigen::AngleAxisd(theta, Vector3d::UnitY()))
          .toRotationMatrix();
  Box b;
  b.T_world_box.linear() = R;
  b.T_world_box.translation() = 0.5 * (lo + hi) - 0.5 * kThickness * R.col(2);
  b.half_extents = Vector3d(0.5 * (hi - lo).norm(), hw, 0.5 * kThickness);
  return b;
}

}  // namespace

void addFarmGround(Scene& s) { s.world.ground(0.0, makeMaterial(Texture::kGrass, {0.3f, 0.42f, 0.2f}, 0.3f, 0.5f, 7)); }

void addBarn(Scene& s, const PlanarPose& c) {
  constexpr double hx = 8.0, hy = 5.0, height = 4.5, door = 2.25, door_height = 3.5;
  const Material walls = brick(11);
  for (const double y : {hy, -hy})
    s.world.structure(verticalRect(c.toWorld(-hx, y), c.toWorld(hx, y), c.z, c.z + height), walls);
  for (const double x : {hx, -hx}) {
    s.world.structure(verticalRect(c.toWorld(x, -hy), c.toWorld(x, -door), c.z, c.z + height), walls);
    s.world.structure(verticalRect(c.toWorld(x, door), c.toWorld(x, hy), c.z, c.z + height), walls);
    s.world.structure(verticalRect(c.toWorld(x, -door), c.toWorld(x, door), c.z + door_height, c.z + height), walls);
  }
  s.world.structure(flatRect(c, 0.0, 0.0, c.z + height, hx + 0.3, hy + 0.3), metal(12));
  s.world.indoor(regionOf(c, -hx, hx, -hy, hy, c.z - 0.5, c.z + height));
  s.occupied.push_back(footprintAlong(c, -hx - 1.0, hx + 1.0, hy + 1.0));
  // Inside, along the walls: a tractor, shelving, a stack of bales.
  const auto inside = [&](double x, double y, const Vector3d& half, const Material& m) {
    const Vector2d p = c.toWorld(x, y);
    s.world.decor(yawBox(Vector3d(p.x(), p.y(), c.z), half, c.heading), m, G::kClearance);
  };
  inside(-3.5, 3.3, {1.5, 0.8, 1.1}, makeMaterial(Texture::kCarPaint, {0.7f, 0.1f, 0.08f}, 0.7f, 1.0f, 13));
  inside(3.0, -4.4, {2.5, 0.35, 1.0}, metal(14));
  inside(-5.0, -3.8, {1.2, 0.6, 0.5}, straw(15));
  inside(4.5, 3.9, {1.0, 0.6, 0.8}, straw(16));
}

void scatterTrees(Scene& s, const Vector2d& lo, const Vector2d& hi, int count) {
  for (int i = 0; i < count; ++i) {
    const auto u = [&](std::uint64_t k) { return s.uniform(kTrees, static_cast<std::uint64_t>(i), k); };
    const Vector2d p(lo.x() + (hi.x() - lo.x()) * u(0), lo.y() + (hi.y() - lo.y()) * u(1));
    const double height = 5.0 + 4.0 * u(2), crown = 1.3 + 1.0 * u(3);
    Footprint f;
    f.center = p;
    f.radius = crown * std::numbers::sqrt2;
    if (std::any_of(s.occupied.begin(), s.occupied.end(), [&](const Footprint& o) { return footprintsOverlap(o, f); }))
      continue;
    s.world.tree(Vector3d(p.x(), p.y(), 0.0), height, crown, static_cast<std::uint32_t>(100 + i), 3.0);
  }
}

void straightRoad(Scene& s, double length) {
  const PlanarPose f = s.course.end();
  s.course.open(Condition::kStraight);
  s.course.straight(length, FarmSpeeds::kRoad);
  s.course.close(Condition::kStraight);
  constexpr double kPanel = 4.0, kOffset = 4.0;
  for (double x = 0.0; x + kPanel <= length + 1e-9; x += kPanel) {
    for (const double y : {kOffset, -kOffset})
      s.world.decor(verticalRect(f.toWorld(x, y), f.toWorld(x + kPanel, y), f.z, f.z + 1.2), fence(21), G::kClearance);
  }
}

void mound(Scene& s, bool up, bool down, double platform) {
  const double lt = Course::kRampTransition, run = G::kRampRun, g = G::kRampGrade, rise = g * run, hw = 2.0;
  const PlanarPose f = s.course.end();
  const double z0 = up ? f.z : f.z - rise;  // ground under the mound
  const Material m = concrete(31);
  double x = 0.0;  // ideal start of the next element along f
  if (up) {
    s.course.open(Condition::kUphill);
    s.course.ramp(run, g, FarmSpeeds::kRamp);
    s.course.close(Condition::kUphill);
    s.world.structure(rampSlab(f, lt / 2, lt / 2 + run, z0, z0 + rise, hw), m);
    x = lt / 2 + run;
  } else {
    x = -4.0;  // the platform reaches behind the start
  }
  const double x_top = x;
  // up and down: the ideal platform is `platform` long; one end only: it reaches 4 m past the stop / start.
  const double top_len = (up && down) ? platform : platform + lt / 2 + 4.0;
  s.course.straight((up && down) ? platform - lt : platform, FarmSpeeds::kRamp);
  const Vector2d mid = f.toWorld(x_top + top_len / 2, 0.0);
  s.world.structure(yawBox(Vector3d(mid.x(), mid.y(), z0), Vector3d(top_len / 2, hw, rise / 2), f.heading), m);
  const double x_down = x_top + top_len;
  if (down) {
    s.course.open(Condition::kDownhill);
    s.course.ramp(run, -g, FarmSpeeds::kRamp);
    s.course.close(Condition::kDownhill);
    s.world.structure(rampSlab(f, x_down, x_down + run, z0 + rise, z0, hw), m);
  }
  const double x_first = up ? x_top - run : x_top, x_last = down ? x_down + run : x_down;
  s.occupied.push_back(footprintAlong(f, x_first - 1.0, x_last + 1.0, hw + 1.0));
}

void jolting(Scene& s, double length) {
  const PlanarPose f = s.course.end();
  s.course.open(Condition::kJolting);
  s.course.straight(length, FarmSpeeds::kJolting);
  s.course.close(Condition::kJolting);
  s.world.structure(flatRect(f, length / 2, 0.0, f.z + 0.01, length / 2, 1.5), straw(41));
  for (int i = 0; i * 5.0 < length; ++i) {
    const auto u = [&](std::uint64_t k) { return s.uniform(kBales, static_cast<std::uint64_t>(i), k); };
    const double y = (i % 2 ? 1.0 : -1.0) * (3.0 + u(0));
    const Vector2d p = f.toWorld(i * 5.0 + 2.0 * u(1), y);
    s.world.decor(yawBox(Vector3d(p.x(), p.y(), f.z), {0.6, 0.4, 0.4}, f.heading + u(2)), straw(42 + i), G::kClearance);
  }
}

void corridor(Scene& s, double behind, double length) {
  const PlanarPose f = s.course.end();
  const double x0 = -behind, x1 = x0 + G::kCorridorLength, hw = G::kCorridorHalfWidth;
  s.course.open(Condition::kCorridor);
  s.course.straight(length, FarmSpeeds::kDegraded);
  s.course.close(Condition::kCorridor);
  wallsAlong(s, f, x0, x1, hw, 3.0, 5.0, concrete(51));  // identical panels: one material, one seed
  // Nothing visible along the axis through the open ends (lidar range 100 m), nor beside the walls.
  s.world.keepOut(footprintAlong(f, x0 - 30.0, x1 + 30.0, 12.0));
  s.world.keepOut(footprintAlong(f, x0 - 100.0, x0, 28.0));
  s.world.keepOut(footprintAlong(f, x1, x1 + 100.0, 28.0));
  s.occupied.push_back(footprintAlong(f, x0, x1, hw + 1.0));
}

void whiteWalls(Scene& s, double length) {
  const PlanarPose f = s.course.end();
  s.course.open(Condition::kWhiteWalls);
  s.course.straight(length, FarmSpeeds::kDegraded);
  s.course.close(Condition::kWhiteWalls);
  wallsAlong(s, f, 0.0, length, G::kWhiteHalfWidth, 3.0, length, white());
  s.world.structure(flatRect(f, length / 2, 0.0, f.z + 0.01, length / 2, G::kWhiteHalfWidth), white());
  s.occupied.push_back(footprintAlong(f, 0.0, length, G::kWhiteHalfWidth + 1.0));
}

void lightingShed(Scene& s, double length) {
  constexpr double hw = 3.5, height = 3.2;
  const PlanarPose f = s.course.end();
  s.course.open(Condition::kLighting);
  s.course.straight(length, FarmSpeeds::kDegraded);
  s.course.close(Condition::kLighting);
  wallsAlong(s, f, 0.0, length, hw, height, 6.0, brick(61));
  s.world.structure(flatRect(f, length / 2, 0.0, f.z + height, length / 2 + 0.3, hw + 0.3), metal(62));
  s.world.indoor(regionOf(f, 0.0, length, -hw, hw, f.z - 0.5, f.z + height));
  for (int i = 0; 6.0 * i + 3.0 < length; ++i) {  // pens of straw along both walls
    for (const double y : {hw - 0.5, -(hw - 0.5)}) {
      const Vector2d p = f.toWorld(6.0 * i + 3.0, y);
      s.world.decor(yawBox(Vector3d(p.x(), p.y(), f.z), {1.0, 0.4, 0.4}, f.heading), straw(63 + i), G::kClearance);
    }
  }
  s.occupied.push_back(footprintAlong(f, 0.0, length, hw + 1.0));
}

void sharpTurns(Scene& s) {
  constexpr double r = 1.5, v = FarmSpeeds::kSharp;
  const PlanarPose f = s.course.end();
  s.course.open(Condition::kSharpTurns);
  s.course.straight(2.0, v);
  s.course.arc(kPi / 2, r, v);
  s.course.straight(4.0, v);
  s.course.arc(-3 * kPi / 4, r, v);
  s.course.straight(4.0, v);
  s.course.arc(3 * kPi / 4, r, v);
  s.course.straight(4.0, v);
  s.course.arc(-kPi / 2, r, v);
  s.course.straight(2.0, v);
  s.course.close(Condition::kSharpTurns);
  // Pens (4 m squares of kPen panels) on a grid around the turns; panels too near the path are left out.
  int n = 0;
  for (double x = -6.0; x <= 20.0; x += 6.0) {
    for (double y = -8.0; y <= 18.0; y += 6.0, ++n) {
      const Vector2d c = f.toWorld(x, y);
      const PlanarPose pf{c, f.heading, f.z};
      const Vector2d corners[4] = {pf.toWorld(-2, -2), pf.toWorld(2, -2), pf.toWorld(2, 2), pf.toWorld(-2, 2)};
      for (int k = 0; k < 4; ++k)
        s.world.decor(verticalRect(corners[k], corners[(k + 1) % 4], f.z, f.z + 1.1), pen(70 + n), G::kClearance);
      if (s.uniform(kPens, static_cast<std::uint64_t>(n)) < 0.5)  // a bale inside some pens
        s.world.decor(yawBox(Vector3d(c.x(), c.y(), f.z), {0.6, 0.4, 0.4}, f.heading), straw(90 + n), G::kClearance);
    }
  }
}

}  // namespace drover::sim::detail
