// The step every scenario shares: revisit labels, lighting events, jolting vibrations, the requested duration
// (cut, lapped or held) and the spline fit.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "sim/scenario_internal.hpp"

namespace drover::sim::detail {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Undulating jolting of a crawler on rough ground: vertical bounce and pitch/roll rocking at a few Hz.
std::vector<Vibration> joltingVibrations(const Segment& seg) {
  struct Term {
    Vibration::Axis axis;
    double amplitude, frequency, phase;
  };
  const Term terms[] = {
      {Vibration::Axis::kZ, 0.015, 2.5, 0.0},          {Vibration::Axis::kZ, 0.004, 6.1, 1.0},
      {Vibration::Axis::kPitch, 1.5 * kDeg, 1.8, 0.5}, {Vibration::Axis::kPitch, 0.5 * kDeg, 4.4, 2.0},
      {Vibration::Axis::kRoll, 2.0 * kDeg, 1.3, 1.5},  {Vibration::Axis::kRoll, 0.6 * kDeg, 3.7, 0.3}};
  std::vector<Vibration> out;
  const Time ramp = std::min<Time>(500'000'000, (seg.end - seg.start) / 3);
  if (ramp <= 0) return out;
  for (const Term& t : terms) {
    Vibration v;
    v.axis = t.axis;
    v.amplitude = t.amplitude;
    v.frequency = t.frequency;
    v.phase = t.phase;
    v.start = seg.start;
    v.end = seg.end;
    v.ramp = ramp;
    out.push_back(v);
  }
  return out;
}

double wrapAngle(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

bool endsAtStart(const std::vector<PathSample>& s) {
  return (s.back().p_world - s.front().p_world).norm() < 0.5 &&
         std::abs(wrapAngle(s.back().yaw - s.front().yaw)) < 5.0 * kDeg;
}

// Cuts, laps or holds the samples (and their segments) to cover [0, duration].
void applyDuration(std::vector<PathSample>& s, std::vector<Segment>& segments, double duration_s, bool laps) {
  if (duration_s == 0.0) return;
  const Time knot = s[1].t - s[0].t;
  const Time end = (fromSeconds(duration_s) + knot - 1) / knot * knot;  // first knot at or after the duration
  if (end < 3 * knot)
    throw std::invalid_argument("makeScenario: duration_s too short for a trajectory, got " +
                                std::to_string(duration_s));
  const std::vector<PathSample> lap = s;
  const std::vector<Segment> lap_segments = segments;
  const Time period = lap.back().t;
  for (int k = 1; s.back().t < end; ++k) {
    if (!laps) {  // open course: rest at the end pose, if it ends at rest
      if ((lap.back().p_world - lap[lap.size() - 2].p_world).norm() > 1e-9)
        throw std::invalid_argument("makeScenario: duration_s " + std::to_string(duration_s) +
                                    " s exceeds this path, which ends moving, at " + std::to_string(toSeconds(period)) +
                                    " s");
      PathSample rest = s.back();
      rest.t += knot;
      s.push_back(rest);
      continue;
    }
    for (std::size_t j = 1; j < lap.size(); ++j) {
      PathSample q = lap[j];
      q.t += k * period;
      q.p_world += k * (lap.back().p_world - lap.front().p_world);
      q.yaw += k * (lap.back().yaw - lap.front().yaw);
      s.push_back(q);
    }
    for (Segment g : lap_segments) {
      g.start += k * period, g.end += k * period;
      segments.push_back(g);
    }
  }
  while (s.back().t > end) s.pop_back();
  std::vector<Segment> kept;
  for (Segment g : segments) {
    g.end = std::min(g.end, end);
    if (g.start < g.end) kept.push_back(g);
  }
  segments = kept;
}

}  // namespace

std::vector<Segment> revisitSegments(const std::vector<PathSample>& samples, double radius, double min_gap_s) {
  const auto key = [&](const Eigen::Vector3d& p, int dx, int dy) {
    return (static_cast<std::int64_t>(std::floor(p.x() / radius)) + dx) * 1'000'003LL +
           static_cast<std::int64_t>(std::floor(p.y() / radius)) + dy;
  };
  std::unordered_map<std::int64_t, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < samples.size(); ++i) grid[key(samples[i].p_world, 0, 0)].push_back(i);
  const Time gap = fromSeconds(min_gap_s);
  std::vector<Segment> spans;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    bool revisit = false;
    for (int dx = -1; dx <= 1 && !revisit; ++dx) {
      for (int dy = -1; dy <= 1 && !revisit; ++dy) {
        const auto it = grid.find(key(samples[i].p_world, dx, dy));
        if (it == grid.end()) continue;
        for (const std::size_t j : it->second) {
          if (samples[j].t > samples[i].t - gap) break;  // indices (and times) increase within a cell
          if ((samples[j].p_world - samples[i].p_world).norm() < radius) {
            revisit = true;
            break;
          }
        }
      }
    }
    if (!revisit) continue;
    const Time t = samples[i].t;
    if (!spans.empty() && t - spans.back().end <= 2 * kNanosPerSecond) {
      spans.back().end = t;  // joins the previous span across short gaps
    } else {
      spans.push_back({Condition::kOverlap, t, t});
    }
  }
  std::erase_if(spans, [](const Segment& s) { return s.end - s.start < kNanosPerSecond; });
  return spans;
}

Scenario finishScenario(ScenarioParts parts, const ScenarioOptions& options) {
  if (parts.samples.size() < 4) throw std::invalid_argument("finishScenario: fewer than 4 samples in " + parts.name);
  const bool loops = endsAtStart(parts.samples);
  for (const Segment& r : revisitSegments(parts.samples)) parts.segments.push_back(r);
  applyDuration(parts.samples, parts.segments, options.duration_s, loops);
  std::stable_sort(parts.segments.begin(), parts.segments.end(),
                   [](const Segment& a, const Segment& b) { return a.start < b.start; });

  std::vector<Vibration> vibrations;
  for (const Segment& seg : parts.segments) {
    if (seg.condition == Condition::kJolting) {
      for (const Vibration& v : joltingVibrations(seg)) vibrations.push_back(v);
    }
    if (seg.condition == Condition::kLighting) parts.lighting.events.push_back({seg.start, seg.end});
  }
  Scenario out;
  out.name = parts.name;
  out.world = parts.world;
  out.trajectory = std::make_shared<const SplineTrajectory>(parts.samples, vibrations);
  out.illumination = makeIllumination(parts.lighting);
  out.closes_loop = loops || std::any_of(parts.segments.begin(), parts.segments.end(),
                                         [](const Segment& s) { return s.condition == Condition::kOverlap; });
  out.segments = std::move(parts.segments);
  for (Time t = out.trajectory->startTime(); t <= out.trajectory->endTime(); t += 100'000'000)
    out.max_speed = std::max(out.max_speed, out.trajectory->at(t).v_world.norm());
  return out;
}

}  // namespace drover::sim::detail
