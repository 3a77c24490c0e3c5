#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>

#include "sim/scenario.hpp"
#include "sim/scenario_probe.hpp"

namespace drover::sim {
namespace {

using Eigen::Vector3d;
using G = CourseGeometry;
using probe::headingOf;
using probe::nearestObstacle;
constexpr Time kTenHz = 100'000'000;

// Scenarios are deterministic: build each once for the whole file.
const Scenario& scenario(const std::string& name) {
  static std::map<std::string, Scenario> cache;
  auto it = cache.find(name);
  if (it == cache.end()) it = cache.emplace(name, makeScenario(name, ScenarioOptions{})).first;
  return it->second;
}

std::vector<std::string> courseNames() {
  std::vector<std::string> names = scenarioNames();
  std::erase(names, "kitti05-replay");
  std::erase(names, "mav-room");  // flies: test_scenario_mav.cpp
  return names;
}

const Segment* findSegment(const Scenario& s, Condition c) {
  for (const Segment& seg : s.segments)
    if (seg.condition == c) return &seg;
  return nullptr;
}

Vector3d position(const Scenario& s, Time t) { return s.trajectory->pose(t).translation(); }

double wrap(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

// ---- every scenario --------------------------------------------------------------------------------------------

TEST(Scenario, EveryCourseNameBuildsWithItsOwnConditionLabelledAndAtRestAtBothEnds) {
  const std::map<std::string, Condition> own = {
      {"uphill", Condition::kUphill},          {"downhill", Condition::kDownhill},
      {"garage-exit", Condition::kGarageExit}, {"garage-entry", Condition::kGarageEntry},
      {"jolting", Condition::kJolting},        {"straight", Condition::kStraight},
      {"overlap", Condition::kOverlap},        {"sharp-turns", Condition::kSharpTurns},
      {"white-walls", Condition::kWhiteWalls}, {"corridor", Condition::kCorridor},
      {"lighting", Condition::kLighting}};
  for (const std::string& name : courseNames()) {
    SCOPED_TRACE(name);
    const Scenario& s = scenario(name);
    EXPECT_EQ(s.name, name);
    ASSERT_NE(s.trajectory, nullptr);
    EXPECT_GT(s.world.primitiveCount(), 10u);
    EXPECT_LT(s.world.primitiveCount(), 500u);
    ASSERT_TRUE(static_cast<bool>(s.illumination));
    EXPECT_LT(s.trajectory->at(s.trajectory->startTime()).v_world.norm(), 1e-3);
    EXPECT_LT(s.trajectory->at(s.trajectory->endTime()).v_world.norm(), 1e-3);
    for (std::size_t i = 1; i < s.segments.size(); ++i) EXPECT_LE(s.segments[i - 1].start, s.segments[i].start);
    if (name == "farm") continue;
    const double duration = toSeconds(s.trajectory->endTime() - s.trajectory->startTime());
    EXPECT_GE(duration, 30.0);
    EXPECT_LE(duration, 90.0);
    EXPECT_NE(findSegment(s, own.at(name)), nullptr) << "missing label " << conditionName(own.at(name));
  }
}

TEST(Scenario, UnknownNameThrowsListingTheKnownNames) {
  try {
    makeScenario("moon-base", ScenarioOptions{});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("moon-base"), std::string::npos);
    for (const std::string& n : scenarioNames()) EXPECT_NE(what.find(n), std::string::npos) << n;
  }
}

TEST(Scenario, KittiReplayWithoutGroundTruthThrows) {
  EXPECT_THROW(makeScenario("kitti05-replay", ScenarioOptions{}), std::invalid_argument);
}

TEST(Scenario, NoPrimitiveComesWithinOneMetreOfAnyCoursePath) {
  for (const std::string& name : courseNames()) {
    SCOPED_TRACE(name);
    const Scenario& s = scenario(name);
    for (Time t = s.trajectory->startTime(); t <= s.trajectory->endTime(); t += 5 * kTenHz)
      ASSERT_GE(nearestObstacle(s, t, 1.0), 1.0) << "at t = " << toSeconds(t) << " s";
    // Straight down: the surface driven on, kBodyHeight below (jolting adds its bounce of a few cm).
    for (Time t = s.trajectory->startTime(); t <= s.trajectory->endTime(); t += 5 * kTenHz) {
      const Vector3d o = position(s, t);
      const auto hit = s.world.intersect({o, -Vector3d::UnitZ()});
      ASSERT_TRUE(hit.has_value());
      EXPECT_NEAR(hit->distance, G::kBodyHeight, 0.05) << "at t = " << toSeconds(t) << " s";
    }
  }
}

// ---- the farm --------------------------------------------------------------------------------------------------

TEST(FarmScenario, IsAClosedCourseOf550To700MetresEndingAtRestWhereItStarted) {
  const Scenario& farm = scenario("farm");
  const SplineTrajectory& traj = *farm.trajectory;
  EXPECT_GE(traj.pathLength(), 550.0);
  EXPECT_LE(traj.pathLength(), 700.0);
  const Eigen::Isometry3d first = traj.pose(traj.startTime()), last = traj.pose(traj.endTime());
  EXPECT_LT((last.translation() - first.translation()).norm(), 0.5);
  EXPECT_LT(std::abs(wrap(headingOf(last) - headingOf(first))), 3.0 * std::numbers::pi / 180);
  EXPECT_TRUE(farm.closes_loop);
  // At rest for the first 2 s (static IMU initialisation; the interpolating spline rings ~1e-3 m/s just before
  // the start).
  for (Time t = 0; t <= 1'500'000'000; t += kTenHz) EXPECT_LT(traj.at(t).v_world.norm(), 1e-3) << toSeconds(t);
}

TEST(FarmScenario, NeverExceedsTheCrawlersTopSpeed) {
  const Scenario& farm = scenario("farm");
  double top = 0.0;
  for (Time t = farm.trajectory->startTime(); t <= farm.trajectory->endTime(); t += kTenHz)
    top = std::max(top, farm.trajectory->at(t).v_world.norm());
  EXPECT_LE(top, G::kFarmMaxSpeed);
  EXPECT_GT(top, 1.0);  // and does reach crawler speed on the road
  EXPECT_NEAR(farm.max_speed, top, 1e-9);
}

TEST(FarmScenario, LabelsAllElevenConditions) {
  std::set<Condition> seen;
  for (const Segment& s : scenario("farm").segments) {
    EXPECT_LT(s.start, s.end) << conditionName(s.condition);
    seen.insert(s.condition);
  }
  EXPECT_EQ(seen.size(), 11u);
}

TEST(FarmScenario, RevisitsTheFencedRoadAndTheBarnInTheOverlapSpans) {
  const Scenario& farm = scenario("farm");
  int spans = 0;
  for (const Segment& s : farm.segments) {
    if (s.condition != Condition::kOverlap) continue;
    ++spans;
    const Vector3d p = position(farm, (s.start + s.end) / 2);
    // Somewhere driven at least 30 s before, within 2 m.
    double nearest = 1e9;
    for (Time t = 0; t + 30 * kNanosPerSecond <= s.start; t += kTenHz)
      nearest = std::min(nearest, (position(farm, t) - p).norm());
    EXPECT_LT(nearest, 2.0);
  }
  EXPECT_GE(spans, 1);
}

// ---- single conditions -----------------------------------------------------------------------------------------

// On the constant-grade middle of a ramp the body's x axis points along the slope, nose up for uphill.
void expectRampAttitude(const Scenario& s, Condition c, double grade) {
  const Segment* seg = findSegment(s, c);
  ASSERT_NE(seg, nullptr);
  const Time mid = (seg->start + seg->end) / 2;
  const BodyState state = s.trajectory->at(mid);
  const Vector3d x_axis = state.T_world_body.linear().col(0);
  EXPECT_NEAR(x_axis.z(), std::sin(std::atan(grade)), 2e-3);
  EXPECT_GT(state.v_world.normalized().dot(x_axis), 0.9999);
  const double pitch = std::asin(-state.T_world_body.linear()(2, 0));  // Z-Y-X, positive = nose down
  EXPECT_NEAR(pitch, -std::atan(grade), 2e-3);
}

TEST(UphillScenario, RisesByTheRampHeightWithTheNoseUp) {
  const Scenario& s = scenario("uphill");
  const double rise = position(s, s.trajectory->endTime()).z() - position(s, s.trajectory->startTime()).z();
  EXPECT_NEAR(rise, G::kRampGrade * G::kRampRun, 1e-3);  // 1.5 m
  expectRampAttitude(s, Condition::kUphill, G::kRampGrade);
}

TEST(DownhillScenario, DescendsByTheRampHeightWithTheNoseDown) {
  const Scenario& s = scenario("downhill");
  const double drop = position(s, s.trajectory->startTime()).z() - position(s, s.trajectory->endTime()).z();
  EXPECT_NEAR(drop, G::kRampGrade * G::kRampRun, 1e-3);
  expectRampAttitude(s, Condition::kDownhill, -G::kRampGrade);
}

// Horizontal rays from the middle of the corridor: left and right hit its walls at the half width; in every
// other direction whatever is hit within lidar range (100 m) lies in the plane of one of the two walls.
void expectBareCorridor(const Scenario& s) {
  const Segment* seg = findSegment(s, Condition::kCorridor);
  ASSERT_NE(seg, nullptr);
  const Time span = seg->end - seg->start;
  for (Time t = seg->start + span / 5; t <= seg->end - span / 5; t += 10 * kTenHz) {
    const Eigen::Isometry3d T = s.trajectory->pose(t);
    const Vector3d o = T.translation(), left = T.linear().col(1);
    for (const double side : {1.0, -1.0}) {
      const auto hit = s.world.intersect({o, side * left});
      ASSERT_TRUE(hit.has_value());
      EXPECT_NEAR(hit->distance, G::kCorridorHalfWidth, 0.01);
      EXPECT_EQ(hit->material->texture, Texture::kConcrete);
    }
    const double h = headingOf(T);
    for (int k = 0; k < 72; ++k) {
      const double a = h + k * std::numbers::pi / 36;
      const auto hit = s.world.intersect({o, Vector3d(std::cos(a), std::sin(a), 0.0)}, 1e-4, 100.0);
      if (!hit) continue;
      EXPECT_NEAR(std::abs((hit->point - o).dot(left)), G::kCorridorHalfWidth, 0.01) << "direction " << 5 * k << " deg";
    }
  }
}

TEST(CorridorScenario, HasBareWallsAtItsHalfWidthAndNothingElseInLidarRange) {
  expectBareCorridor(scenario("corridor"));
}
TEST(FarmScenario, CorridorStretchHasNothingElseInLidarRange) { expectBareCorridor(scenario("farm")); }

TEST(WhiteWallsScenario, SurroundsThePathWithTexturelessWhiteWallsAndFloor) {
  for (const std::string name : {"white-walls", "farm"}) {
    SCOPED_TRACE(name);
    const Scenario& s = scenario(name);
    const Segment* seg = findSegment(s, Condition::kWhiteWalls);
    ASSERT_NE(seg, nullptr);
    const Eigen::Isometry3d T = s.trajectory->pose((seg->start + seg->end) / 2);
    const Vector3d o = T.translation();
    for (const Vector3d& d :
         {Vector3d(T.linear().col(1)), Vector3d(-T.linear().col(1)), Vector3d(-Vector3d::UnitZ())}) {
      const auto hit = s.world.intersect({o, d});
      ASSERT_TRUE(hit.has_value());
      EXPECT_EQ(hit->material->texture, Texture::kWhite);
    }
    EXPECT_NEAR(s.world.intersect({o, T.linear().col(1)})->distance, G::kWhiteHalfWidth, 0.01);
  }
}

TEST(GarageScenarios, ExitGoesFromIndoorsToOutdoorsAndEntryTheOtherWay) {
  const Scenario& exit = scenario("garage-exit");
  const Scenario& entry = scenario("garage-entry");
  EXPECT_TRUE(exit.world.isIndoor(position(exit, exit.trajectory->startTime())));
  EXPECT_FALSE(exit.world.isIndoor(position(exit, exit.trajectory->endTime())));
  EXPECT_FALSE(entry.world.isIndoor(position(entry, entry.trajectory->startTime())));
  EXPECT_TRUE(entry.world.isIndoor(position(entry, entry.trajectory->endTime())));
  // Indoor light is half of daylight; the garage has a roof over the robot.
  const Vector3d inside = position(exit, 0);
  EXPECT_FLOAT_EQ(exit.illumination(0, inside), 0.5f);
  EXPECT_FLOAT_EQ(exit.illumination(0, Vector3d(500, 500, 0)), 1.0f);
  const auto roof = exit.world.intersect({inside, Vector3d::UnitZ()});
  ASSERT_TRUE(roof.has_value());
  EXPECT_NEAR(roof->distance, 4.5 - G::kBodyHeight, 1e-6);
}

TEST(LightingScenario, RampsToDarkAndBackThenFlickersWithinItsSpanOnly) {
  const Scenario& s = scenario("lighting");
  const Segment* seg = findSegment(s, Condition::kLighting);
  ASSERT_NE(seg, nullptr);
  const Vector3d outdoors(1000, 1000, 0);
  const Time span = seg->end - seg->start;
  const auto at = [&](double u) { return s.illumination(seg->start + static_cast<Time>(u * span), outdoors); };
  EXPECT_FLOAT_EQ(s.illumination(seg->start - kTenHz, outdoors), 1.0f);
  EXPECT_FLOAT_EQ(s.illumination(seg->end + kTenHz, outdoors), 1.0f);
  // Halfway down the ramp (smoothstep of the exponent: geometric, 1 -> 5e-4 over 3.3 decades) and dark (a night level).
  EXPECT_NEAR(at(0.1), std::sqrt(5e-4f), 1e-5);
  EXPECT_FLOAT_EQ(at(0.3), 5e-4f);
  float lo = 1.0f, hi = 0.0f;         // flicker of depth 0.3
  for (double u = 0.62; u < 1.0; u += 0.0005) lo = std::min(lo, at(u)), hi = std::max(hi, at(u));
  EXPECT_NEAR(lo, 0.7f, 2e-3);
  EXPECT_NEAR(hi, 1.0f, 2e-3);
}

TEST(JoltingScenario, BouncesAndRocksOnlyWithinItsSpan) {
  const Scenario& s = scenario("jolting");
  const Segment* seg = findSegment(s, Condition::kJolting);
  ASSERT_NE(seg, nullptr);
  double z_lo = 1e9, z_hi = -1e9, rate = 0.0;
  for (Time t = seg->start + kNanosPerSecond; t < seg->end - kNanosPerSecond; t += kTenHz / 10) {
    const BodyState b = s.trajectory->at(t);
    z_lo = std::min(z_lo, b.T_world_body.translation().z()), z_hi = std::max(z_hi, b.T_world_body.translation().z());
    rate = std::max(rate, b.omega_body.head<2>().norm());
  }
  EXPECT_GT(z_hi - z_lo, 0.02);  // ~2 cm bounce
  EXPECT_LT(z_hi - z_lo, 0.06);
  EXPECT_GT(rate, 0.1);  // [rad/s] pitch/roll rocking at a few Hz
  for (Time t = 0; t < seg->start - kNanosPerSecond; t += kTenHz) {
    const BodyState b = s.trajectory->at(t);
    EXPECT_NEAR(b.T_world_body.translation().z(), G::kBodyHeight, 1e-6);
    EXPECT_LT(b.omega_body.norm(), 1e-6);
  }
}

TEST(OverlapScenario, ComesBackOverItsFirstStretchAfterOneLap) {
  const Scenario& s = scenario("overlap");
  EXPECT_TRUE(s.closes_loop);
  const Segment* seg = findSegment(s, Condition::kOverlap);
  ASSERT_NE(seg, nullptr);
  EXPECT_GT(toSeconds(seg->end - seg->start), 15.0);
  // One lap of the rounded rectangle (57.1 m) brings the robot back through its start.
  EXPECT_LT((position(s, seg->start) - position(s, 0)).norm(), 2.5);
}

TEST(SharpTurnsScenario, TurnsBy90To135DegreesAtSmallRadius) {
  const Scenario& s = scenario("sharp-turns");
  const Segment* seg = findSegment(s, Condition::kSharpTurns);
  ASSERT_NE(seg, nullptr);
  double top_rate = 0.0;
  for (Time t = seg->start; t < seg->end; t += kTenHz)
    top_rate = std::max(top_rate, std::abs(s.trajectory->at(t).omega_body.z()));
  EXPECT_GT(top_rate, 0.25);  // ~0.5 m/s on a 1.5 m radius: 0.33 rad/s
  // Net heading change over the chicane is zero (left 90, right 135, left 135, right 90).
  const double before = headingOf(s.trajectory->pose(seg->start)), after = headingOf(s.trajectory->pose(seg->end));
  EXPECT_NEAR(wrap(after - before), 0.0, 1e-3);
}

// ---- duration ------------------------------------------------------------------------------------------------

TEST(Scenario, DurationCutsAClosedCourseOrDrivesItAgain) {
  ScenarioOptions o;
  o.duration_s = 100.0;
  const Scenario cut = makeScenario("farm", o);
  EXPECT_EQ(cut.trajectory->endTime(), 100 * kNanosPerSecond);
  EXPECT_LT(
      (cut.trajectory->pose(50 * kNanosPerSecond).translation() - position(scenario("farm"), 50 * kNanosPerSecond))
          .norm(),
      1e-9);
  o.duration_s = 1000.0;
  const Scenario laps = makeScenario("farm", o);
  const Time lap = scenario("farm").trajectory->endTime();
  EXPECT_EQ(laps.trajectory->endTime(), 1000 * kNanosPerSecond);
  for (const Time t : {10 * kNanosPerSecond, 100 * kNanosPerSecond, 300 * kNanosPerSecond}) {
    const Eigen::Isometry3d a = laps.trajectory->pose(t), b = laps.trajectory->pose(t + lap);
    EXPECT_LT((a.translation() - b.translation()).norm(), 1e-6);
    EXPECT_LT((a.linear() - b.linear()).norm(), 1e-6);
  }
  int exits = 0;
  for (const Segment& s : laps.segments) exits += s.condition == Condition::kGarageExit;
  EXPECT_EQ(exits, 2);
}

TEST(Scenario, DurationBeyondAnOpenCourseKeepsTheRobotAtRestAtItsEnd) {
  ScenarioOptions o;
  o.duration_s = 80.0;
  const Scenario held = makeScenario("uphill", o);
  const Time natural = scenario("uphill").trajectory->endTime();
  EXPECT_EQ(held.trajectory->endTime(), 80 * kNanosPerSecond);
  EXPECT_LT((position(held, 80 * kNanosPerSecond) - position(scenario("uphill"), natural)).norm(), 1e-9);
  EXPECT_LT(held.trajectory->at(70 * kNanosPerSecond).v_world.norm(), 1e-9);
}

}  // namespace
}  // namespace drover::sim
