#pragma once
// Internal to the scenarios: the step shared by every scenario (labels, lighting, vibrations, duration, spline)
// and the KITTI 05 replay with its procedural town.
#include <cstdint>
#include <string>
#include <vector>

#include "sim/scenario.hpp"
#include "sim/scenario_world.hpp"

namespace drover::sim::detail {

struct ScenarioParts {
  std::string name;
  std::vector<PathSample> samples;  // uniformly spaced from t = 0
  std::vector<Segment> segments;    // labels so far (revisits are found and added by finishScenario)
  World world;                      // built
  LightingPlan lighting;            // lighting events are added for every kLighting segment
};

// Adds kOverlap segments where the path comes back within 2 m of where it was >= 30 s earlier, a lighting event
// per kLighting segment and vibrations over every kJolting segment, applies options.duration_s, fits the spline.
Scenario finishScenario(ScenarioParts parts, const ScenarioOptions& options);

// Spans of samples that revisit a place: within `radius` [m] of a sample at least `min_gap_s` earlier.
std::vector<Segment> revisitSegments(const std::vector<PathSample>& samples, double radius = 2.0,
                                     double min_gap_s = 30.0);

Scenario makeKittiReplay(const Trajectory& ground_truth, const ScenarioOptions& options);
// A micro aerial vehicle's flight in a textured room (scenario_mav.cpp).
Scenario makeMavRoom(const ScenarioOptions& options);
// Facades, trees, parked cars and asphalt along the path (body = camera 0, kKittiCameraHeight above the road).
World buildTown(const std::vector<PathSample>& samples, std::uint64_t seed);

}  // namespace drover::sim::detail
