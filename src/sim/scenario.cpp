// Scenario names and dispatch; course scenarios are timed here and finished in scenario_finish.cpp.
#include "sim/scenario.hpp"

#include <algorithm>
#include <stdexcept>

#include "sim/farm_layout.hpp"
#include "sim/scenario_internal.hpp"

namespace drover::sim {

std::string conditionName(Condition c) {
  switch (c) {
    case Condition::kUphill:
      return "uphill";
    case Condition::kDownhill:
      return "downhill";
    case Condition::kGarageExit:
      return "garage-exit";
    case Condition::kGarageEntry:
      return "garage-entry";
    case Condition::kJolting:
      return "jolting";
    case Condition::kStraight:
      return "straight";
    case Condition::kOverlap:
      return "overlap";
    case Condition::kSharpTurns:
      return "sharp-turns";
    case Condition::kWhiteWalls:
      return "white-walls";
    case Condition::kCorridor:
      return "corridor";
    case Condition::kLighting:
      return "lighting";
  }
  throw std::invalid_argument("conditionName: unknown condition " + std::to_string(static_cast<int>(c)));
}

std::vector<std::string> scenarioNames() {
  return {"uphill",      "downhill",    "garage-exit", "garage-entry", "jolting", "straight",      "overlap",
          "sharp-turns", "white-walls", "corridor",    "lighting",     "farm",    "kitti05-replay", "mav-room"};
}

namespace {

std::string knownNames() {
  std::string all;
  for (const std::string& n : scenarioNames()) all += (all.empty() ? "" : ", ") + n;
  return all;
}

Scenario makeCourse(const std::string& name, const ScenarioOptions& options) {
  detail::Scene scene;
  scene.seed = options.seed;
  if (name == "farm") {
    detail::buildFarm(scene);
  } else {
    detail::buildSingle(name, scene);
  }
  const detail::TimedCourse timed = detail::timeCourse(scene.course, detail::ProfileOptions{});
  detail::ScenarioParts parts;
  parts.name = name;
  parts.samples = timed.samples;
  parts.segments = timed.segments;
  parts.lighting = scene.lighting;
  parts.lighting.indoor_regions = scene.world.indoorRegions();
  parts.world = scene.world.finish(detail::PathIndex(scene.course.polyline(0.25)));
  return detail::finishScenario(std::move(parts), options);
}

}  // namespace

Scenario makeScenario(const std::string& name, const ScenarioOptions& options) {
  if (!(options.duration_s >= 0.0))
    throw std::invalid_argument("makeScenario: duration_s must be >= 0, got " + std::to_string(options.duration_s));
  if (name == "kitti05-replay") {
    if (options.kitti05_ground_truth == nullptr)
      throw std::invalid_argument("makeScenario: kitti05-replay needs options.kitti05_ground_truth (KITTI poses 05)");
    return detail::makeKittiReplay(*options.kitti05_ground_truth, options);
  }
  if (name == "mav-room") return detail::makeMavRoom(options);
  const std::vector<std::string> names = scenarioNames();
  if (std::find(names.begin(), names.end(), name) == names.end())
    throw std::invalid_argument("makeScenario: unknown scenario '" + name + "'; known: " + knownNames());
  return makeCourse(name, options);
}

}  // namespace drover::sim
