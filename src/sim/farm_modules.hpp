#pragma once
// Internal to the scenarios: the building blocks of the livestock-farm course. Each module appends its stretch of
// path straight ahead of the course's current end (labelling its condition) and builds the structures around it;
// the farm strings them together, the single-condition scenarios use one each with a short lead-in and lead-out.
#include <cstdint>
#include <vector>

#include "sim/random.hpp"
#include "sim/scenario_course.hpp"
#include "sim/scenario_world.hpp"

namespace drover::sim::detail {

struct Scene {
  Course course;
  WorldBuilder world;
  LightingPlan lighting;
  std::vector<Footprint> occupied;  // ground taken by structures (no trees there)
  std::uint64_t seed = 1;
  // Deterministic uniform [0, 1) for decoration `category`, item `index`, draw `k`.
  double uniform(std::uint64_t category, std::uint64_t index, std::uint64_t k = 0) const {
    return uniform01(hashKeys(seed, static_cast<std::uint64_t>(Stream::kScenario), category, index, k));
  }
};

// Speeds [m/s] of the crawler on the course's stretches.
struct FarmSpeeds {
  static constexpr double kRoad = 1.18, kTurn = 1.0, kRamp = 0.8, kJolting = 0.8, kGarage = 0.8;
  static constexpr double kDegraded = 1.0, kSharp = 0.5;
};

// Structures (no path): a drive-through barn centred at `centre` (long axis along its heading, which must be a
// multiple of 90 deg: the indoor region is axis-aligned), doors at both ends; ground with the farm's materials.
void addBarn(Scene& scene, const PlanarPose& centre);
void addFarmGround(Scene& scene);
// Trees scattered over [lo, hi] (plane), kept where they clear the path by 3 m.
void scatterTrees(Scene& scene, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int count);

// Path modules (straight ahead of the course end; each labels its own condition).
void straightRoad(Scene& scene, double length);  // kStraight at full speed, fences both sides
// The ramp mound: up (kUphill) and/or down (kDownhill) ramps of CourseGeometry's grade and run around a platform.
// up only: the course stops `platform` m onto the platform; down only: the course starts on the platform (its
// start pose must be at the platform's height) and drives `platform` m before the ramp down.
void mound(Scene& scene, bool up, bool down, double platform);
void jolting(Scene& scene, double length);  // kJolting: straw-covered rough track, bales beside it
// kCorridor: identical flat concrete panels on both sides at kCorridorHalfWidth, open ends; nothing else in
// lidar range along its axis (keep-out zones). The walls begin `behind` m behind the course end (0: at it) and
// the path drives `length` m of the corridor's kCorridorLength.
void corridor(Scene& scene, double behind, double length);
void whiteWalls(Scene& scene, double length);    // kWhiteWalls: textureless white walls and floor
void lightingShed(Scene& scene, double length);  // kLighting: a roofed open-ended shed (lighting events by time)
void sharpTurns(Scene& scene);                   // kSharpTurns: 90-135 deg turns at 1.5 m radius among pens

}  // namespace drover::sim::detail
