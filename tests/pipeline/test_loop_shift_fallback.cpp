// The fall-back of the loop closure's prior-narrowed Scan Context shift search (LoopClosureConfig::shift_fallback):
// its reach follows the rotation drift budget, a revisit whose estimated yaw drifted beyond the narrowed window is
// still found within that reach, and the counters say what each policy searched.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <numbers>

#include "pipeline/loop_closure.hpp"
#include "support/courtyard.hpp"
#include "support/units.hpp"

namespace drover::pipeline {
namespace {

using ::drover::test::kPi;

// Keyframe i of a lap of radius 4 m around the courtyard's centre, 10 deg apart, heading along the circle.
Eigen::Isometry3d fallbackLapPose(int i) {
  const double theta = i * 10.0 * kPi / 180.0;
  return test::planarPose(4 * std::cos(theta), 4 * std::sin(theta), i * 10.0 + 90.0);
}

LoopClosureConfig fallbackCourtyardConfig(ShiftFallback fallback) {
  LoopClosureConfig c;
  c.min_age = 15.0;  // keyframes are 1 s apart below
  c.database.exclude_recent = 10;
  c.database.descriptor.lateral_steps = 0;  // one descriptor per query: every search is 7 + the fall-back's shifts
  c.skip_after_loop = 0;
  // The odometry below turns 29 deg too far in a lap, far more than a lidar-inertial odometry does: the rotation
  // budget is opened for it (0.6 rad = 34 deg), as a drifting odometry's would be.
  c.max_rotation_drift_floor = 0.6;
  c.shift_fallback = fallback;
  return c;
}

// A lap whose odometry turns 0.8 deg too far a step: back at the start (36 steps on) the estimate's relative yaw is
// 28.8 deg = 4.8 sectors off the truth, beyond the narrowed window's +-3 sectors. Loops found are applied as the
// LIS does. Returns the loop closure; `closed` counts the accepted loops.
std::unique_ptr<LoopClosure> driftingLap(const LoopClosureConfig& config, int& closed) {
  auto loops = std::make_unique<LoopClosure>(config);
  lidar::LocalMap map;
  Eigen::Isometry3d T_est = fallbackLapPose(0);
  closed = 0;
  for (int i = 0; i <= 40; ++i) {
    if (i > 0) T_est = T_est * fallbackLapPose(i - 1).inverse() * fallbackLapPose(i) * test::planarPose(0, 0, 0.8);
    lidar::FeatureSet f = test::seenFrom(test::courtyard(0), fallbackLapPose(i));
    f.t = fromSeconds(i);
    if (loops->addKeyframe(map, map.addKeyframe(f, T_est), geometry::Matrix6d::Zero())) {
      ++closed;
      const std::vector<Eigen::Isometry3d> poses = loops->poses();
      for (std::size_t k = 0; k < poses.size(); ++k) map.updatePose(k, poses[k]);
      T_est = poses.back();
    }
  }
  return loops;
}

TEST(ShiftFallbackRadius, FollowsTheRotationBudgetInSectorsRoundedUpPlusOne) {
  LoopClosureConfig c;  // budget 0.2 rad + 0.0005 rad/m + 0.05 rad per degenerate rotation; 60 sectors of 6 deg
  c.shift_fallback = ShiftFallback::kBudget;
  // 0.2 rad = 1.91 sectors -> 2 + 1 = 3: within the narrowed window (search_radius 3), so no fall-back at all.
  EXPECT_EQ(shiftFallbackRadius(c, 0.0, 0.0), 3);
  // 1 km: 0.7 rad = 6.68 sectors -> 7 + 1.
  EXPECT_EQ(shiftFallbackRadius(c, 1000.0, 0.0), 8);
  // 2 km: 1.2 rad = 11.46 sectors -> 12 + 1.
  EXPECT_EQ(shiftFallbackRadius(c, 2000.0, 0.0), 13);
  // Degenerate in rotation on the way (a corridor): 20 such directions add 1 rad -> (0.2 + 1.0) rad, 13 again;
  // 60 of them reach past half a turn: every shift.
  EXPECT_EQ(shiftFallbackRadius(c, 0.0, 20.0), 13);
  EXPECT_GE(2 * shiftFallbackRadius(c, 0.0, 60.0) + 1, c.database.descriptor.sectors);
  c.shift_fallback = ShiftFallback::kAlways;
  EXPECT_EQ(shiftFallbackRadius(c, 0.0, 0.0), loop::YawPrior::kFullFallback);
  c.shift_fallback = ShiftFallback::kNever;
  EXPECT_EQ(shiftFallbackRadius(c, 2000.0, 60.0), 0);
}

TEST(LoopShiftFallback, ARevisitWhoseEstimatedYawDriftedBeyondTheWindowIsClosedForFewerShiftsThanTheFullSearch) {
  int closed_always = 0, closed_budget = 0;
  const auto always = driftingLap(fallbackCourtyardConfig(ShiftFallback::kAlways), closed_always);
  const auto budget = driftingLap(fallbackCourtyardConfig(ShiftFallback::kBudget), closed_budget);
  ASSERT_GE(closed_always, 1);
  ASSERT_GE(closed_budget, 1);
  for (const LoopEvent& e : budget->events()) {
    // Each verified candidate's shift is within a sector of the full search's (a window's best under the threshold
    // is kept though it may lie at the window's edge; this courtyard's distance changes little from one sector to
    // the next).
    const int off = std::abs(e.shift - e.full_shift);
    EXPECT_LE(std::min(off, 60 - off), 1) << e.query << " -> " << e.candidate;
    if (!e.verification.accepted) continue;
    // The lap's end back at its start (36 keyframes a lap), within the synthetic verifier's half metre.
    EXPECT_NEAR(double(e.query - e.candidate), 36.0, 2.0);
    const Eigen::Isometry3d T_true = fallbackLapPose(int(e.candidate)).inverse() * fallbackLapPose(int(e.query));
    EXPECT_LT((T_true.inverse() * e.verification.T_candidate_query).translation().norm(), 0.5);
  }
  // Every keyframe of the lap sees the same courtyard, so the full search also offers candidates turned far from
  // the estimate, which take verification slots and are refused: the budget's reach verifies fewer.
  EXPECT_LT(budget->stats().verified, always->stats().verified);
  EXPECT_LT(budget->stats().shifts_evaluated, always->stats().shifts_evaluated);
}

TEST(LoopShiftFallback, TheCountersGiveEachPolicysShiftEvaluations) {
  for (const ShiftFallback f : {ShiftFallback::kAlways, ShiftFallback::kBudget, ShiftFallback::kNever}) {
    int closed = 0;
    const LoopStats s = driftingLap(fallbackCourtyardConfig(f), closed)->stats();
    SCOPED_TRACE(toString(f));
    EXPECT_GT(s.narrowed_searches + s.fallbacks, 0u);
    // The window is 7 shifts; a fall-back adds every shift again (always) or the 2 x (7 - 3) beyond the window
    // within the budget's reach (budget: 0.6 rad + at most 0.015 rad over the lap's 29 m -> 7 sectors).
    const std::size_t fallback_cost = f == ShiftFallback::kAlways ? 60 : f == ShiftFallback::kBudget ? 8 : 0;
    EXPECT_EQ(s.shifts_evaluated, 7 * (s.narrowed_searches + s.fallbacks) + fallback_cost * s.fallbacks);
    if (f == ShiftFallback::kNever) {
      EXPECT_EQ(s.fallbacks, 0u);
    } else {
      EXPECT_GT(s.fallbacks, 0u);
    }
    EXPECT_GT(s.total_ms, s.query_ms);  // the whole call, the shift searches among it
  }
}

TEST(LoopShiftFallback, WithABudgetInsideTheWindowNoCandidateFallsBack) {
  LoopClosureConfig c = fallbackCourtyardConfig(ShiftFallback::kBudget);
  // 0.1 rad + at most 0.015 rad over the lap = 1.1 sectors -> 2 + 1 = 3, the window's own reach.
  c.max_rotation_drift_floor = 0.1;
  int closed = 0;
  const LoopStats s = driftingLap(c, closed)->stats();
  EXPECT_GT(s.narrowed_searches, 0u);
  EXPECT_EQ(s.fallbacks, 0u);
  EXPECT_EQ(s.shifts_evaluated, 7 * s.narrowed_searches);
}

}  // namespace
}  // namespace drover::pipeline
