// Layouts: the ~640 m farm course through every condition, and the single-condition scenarios.
//
// Farm (x east, y north; the crawler starts at rest in a drive-through barn at the origin facing east):
//   garage exit through the east door -> fenced road east (smooth straight) -> south: ramp mound (uphill, platform,
//   downhill), jolting straw track -> west: the repetitive corridor -> north: white walls, the lighting shed,
//   sharp turns among pens -> (Dubins) -> east along the north edge -> south -> west back along the fenced road
//   (revisit, opposite direction) -> round the barn -> garage entry through the west door -> rest at the start.
#include "sim/farm_layout.hpp"

#include <algorithm>
#include <numbers>
#include <stdexcept>

namespace drover::sim::detail {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using G = CourseGeometry;
using V = FarmSpeeds;
constexpr double kPi = std::numbers::pi;

// Trees around the whole course: its bounding box grown by `margin`, `count` candidates.
void treesAround(Scene& s, double margin, int count) {
  Vector2d lo = Vector2d::Constant(1e9), hi = Vector2d::Constant(-1e9);
  for (const Vector2d& p : s.course.polyline(1.0)) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  scatterTrees(s, lo.array() - margin, hi.array() + margin, count);
}

void farmDecor(Scene& s) {
  const Material silo = makeMaterial(Texture::kMetal, {0.7f, 0.72f, 0.75f}, 0.6f, 1.0f, 3);
  for (const double x : {30.0, 38.0}) {
    Cylinder c;
    c.base_center = Vector3d(x, 16.0, 0.0);
    c.radius = 3.0;
    c.height = 12.0;
    s.world.decor(c, silo, G::kClearance);
    s.occupied.push_back({Vector2d(x, 16.0), Vector2d::Zero(), 0.0, 4.0});
  }
  const Box cowshed = yawBox(Vector3d(25.0, -25.0, 0.0), Vector3d(14.0, 8.0, 3.0), 0.0);
  s.world.decor(cowshed, makeMaterial(Texture::kBrick, {0.6f, 0.3f, 0.22f}, 0.5f, 0.25f, 4), G::kClearance);
  s.occupied.push_back(footprintOf(cowshed));
  const Box heap = yawBox(Vector3d(-5.0, -45.0, 0.0), Vector3d(4.0, 3.0, 1.2), 0.4);
  s.world.decor(heap, makeMaterial(Texture::kNoise, {0.3f, 0.25f, 0.18f}, 0.2f, 0.3f, 5), G::kClearance);
  s.occupied.push_back(footprintOf(heap));
}

}  // namespace

void buildFarm(Scene& s) {
  Course& c = s.course;
  addFarmGround(s);
  addBarn(s, PlanarPose{});
  c.open(Condition::kGarageExit);
  c.straight(12.0, V::kGarage);  // through the east door (x = 8) into the yard
  c.close(Condition::kGarageExit);
  straightRoad(s, 40.0);           // x 12 -> 52
  c.arc(-kPi / 2, 6.0, V::kTurn);  // south at (58, -6)
  c.straight(6.0, V::kRoad);
  mound(s, true, true, 8.0);  // 40 m
  c.straight(8.0, V::kRoad);
  jolting(s, 30.0);
  c.straight(6.0, V::kRoad);
  c.arc(-kPi / 2, 6.0, V::kTurn);  // west at (52, -102)
  c.straight(10.0, V::kRoad);
  corridor(s, 0.0, G::kCorridorLength);
  c.straight(14.0, V::kRoad);
  c.arc(-kPi / 2, 6.0, V::kTurn);  // north at (-28, -96)
  c.straight(6.0, V::kRoad);
  whiteWalls(s, 25.0);
  c.straight(8.0, V::kRoad);
  lightingShed(s, 25.0);
  c.straight(6.0, V::kRoad);
  sharpTurns(s);
  c.dubinsTo(PlanarPose{Vector2d(-18.0, 30.0), 0.0, 0.0}, 6.0, V::kTurn);  // east along the north edge
  c.straight(88.0, V::kRoad);
  c.arc(-kPi / 2, 6.0, V::kTurn);  // south at (76, 24)
  c.straight(18.0, V::kRoad);
  c.arc(-kPi / 2, 6.0, V::kTurn);  // west at (70, 0): the fenced road again, the other way
  c.straight(54.0, V::kRoad);
  c.arc(-kPi / 2, 5.0, V::kTurn);  // round the barn's north side
  c.arc(kPi / 2, 5.0, V::kTurn);
  c.straight(20.0, V::kRoad);
  c.arc(kPi, 5.0, V::kTurn);  // east at (-14, 0), facing the west door
  c.open(Condition::kGarageEntry);
  c.straight(14.0, V::kGarage);
  c.close(Condition::kGarageEntry);
  farmDecor(s);
  treesAround(s, 15.0, 90);
}

void buildSingle(const std::string& name, Scene& s) {
  Course& c = s.course;
  addFarmGround(s);
  if (name == "uphill") {
    c.straight(8.0, V::kRoad);
    mound(s, true, false, 8.0);
  } else if (name == "downhill") {
    c = Course(PlanarPose{Vector2d::Zero(), 0.0, G::kRampGrade * G::kRampRun});  // on the platform
    mound(s, false, true, 6.0);
    c.straight(10.0, V::kRoad);
  } else if (name == "garage-exit") {
    addBarn(s, PlanarPose{});
    c = Course(PlanarPose{Vector2d(-4.0, 0.0), 0.0, 0.0});
    c.open(Condition::kGarageExit);
    c.straight(22.0, V::kGarage);
    c.close(Condition::kGarageExit);
  } else if (name == "garage-entry") {
    addBarn(s, PlanarPose{});
    c = Course(PlanarPose{Vector2d(-24.0, 0.0), 0.0, 0.0});
    c.open(Condition::kGarageEntry);
    c.straight(24.0, V::kGarage);
    c.close(Condition::kGarageEntry);
  } else if (name == "jolting") {
    c.straight(6.0, V::kRoad);
    jolting(s, 40.0);
    c.straight(6.0, V::kRoad);
  } else if (name == "straight") {
    straightRoad(s, 60.0);
  } else if (name == "overlap") {
    // Round a shed: one lap of a rounded rectangle and again along its first ~25 m (the revisit).
    const Box shed = yawBox(Vector3d(0.0, 0.0, 0.0), Vector3d(4.5, 2.5, 2.5), 0.0);
    s.world.structure(shed, makeMaterial(Texture::kBrick, {0.55f, 0.3f, 0.2f}, 0.5f, 0.25f, 8));
    s.occupied.push_back(footprintOf(shed));
    c = Course(PlanarPose{Vector2d(0.0, -6.0), 0.0, 0.0});
    for (int lap = 0; lap < 2; ++lap) {
      c.straight(6.0, V::kTurn);
      c.arc(kPi / 2, 4.0, V::kTurn);
      c.straight(4.0, V::kTurn);
      c.arc(kPi / 2, 4.0, V::kTurn);
      if (lap == 1) break;
      c.straight(12.0, V::kTurn);
      c.arc(kPi / 2, 4.0, V::kTurn);
      c.straight(4.0, V::kTurn);
      c.arc(kPi / 2, 4.0, V::kTurn);
      c.straight(6.0, V::kTurn);
    }
    c.straight(2.0, V::kTurn);
  } else if (name == "sharp-turns") {
    c.straight(6.0, V::kRoad);
    sharpTurns(s);
    c.straight(6.0, V::kRoad);
  } else if (name == "white-walls") {
    c.straight(6.0, V::kRoad);
    whiteWalls(s, 30.0);
    c.straight(6.0, V::kRoad);
  } else if (name == "corridor") {
    corridor(s, 6.0, 38.0);  // starts and stops inside
  } else if (name == "lighting") {
    c.straight(6.0, V::kRoad);
    lightingShed(s, 30.0);
    c.straight(6.0, V::kRoad);
  } else {
    throw std::invalid_argument("buildSingle: unknown scenario " + name);
  }
  treesAround(s, 20.0, 30);
}

}  // namespace drover::sim::detail
