// The loop closure's drift budgets run along the cheapest keyframe path where accepted loops are shortcuts
// (pipeline/loop_drift_path.hpp): a place the loops tied a moment ago is held to the odometry since then, not to the
// laps of path between the two keyframes' indices.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "pipeline/loop_closure.hpp"
#include "pipeline/loop_drift_path.hpp"
#include "support/courtyard.hpp"
#include "support/units.hpp"

namespace drover::pipeline {
namespace {

using ::drover::test::kPi;

std::vector<DriftStep> unitSteps(std::size_t n) {
  std::vector<DriftStep> steps(n, DriftStep{1.0, 1.0});
  steps[0] = {};
  return steps;
}

TEST(CheapestDriftPath, WithoutLoopsItIsTheKeyframeChainInEitherDirection) {
  const std::vector<DriftStep> steps = unitSteps(10);
  EXPECT_EQ(cheapestDriftPath(steps, {}, 9, 2).cost, 7.0);
  EXPECT_EQ(cheapestDriftPath(steps, {}, 2, 9).length, 7.0);
  EXPECT_EQ(cheapestDriftPath(steps, {}, 4, 4).cost, 0.0);
}

TEST(CheapestDriftPath, AnAcceptedLoopIsAFreeShortcutAndTheCostsOfTheStepsAreSummedAlongTheCheapestPath) {
  std::vector<DriftStep> steps = unitSteps(20);
  // 18 -> 17 (1) -> loop to 3 -> 2 (1): cost 2 instead of 16 along the chain.
  EXPECT_EQ(cheapestDriftPath(steps, {{3, 17}}, 18, 2).cost, 2.0);
  // Two loops chained (a third pass tied to the second, the second to the first).
  EXPECT_EQ(cheapestDriftPath(steps, {{2, 10}, {10, 19}}, 19, 2).cost, 0.0);
  // A dear step (a degenerate sweep) on the short way (18 -> 17 -> loop -> 3 -> 4): the chain is taken instead,
  // and its length reported.
  steps[4].cost = 100;
  const DriftPath p = cheapestDriftPath(steps, {{3, 17}}, 18, 4);
  EXPECT_EQ(p.cost, 14.0);
  EXPECT_EQ(p.length, 14.0);
  // A loop to a keyframe the steps do not cover yet is ignored.
  EXPECT_EQ(cheapestDriftPath(unitSteps(5), {{1, 7}}, 4, 0).cost, 4.0);
  EXPECT_THROW(cheapestDriftPath(unitSteps(5), {}, 5, 0), std::invalid_argument);
}

// Keyframe i on a circle of radius 4 m around the courtyard's centre, 10 deg apart, heading along it; 36 a lap.
Eigen::Isometry3d driftLapPose(int i) {
  const double theta = i * 10.0 * kPi / 180.0;
  return test::planarPose(4 * std::cos(theta), 4 * std::sin(theta), i * 10.0 + 90.0);
}

// Two laps with exact odometry, except that the first lap's keyframes 12..15 stand in the map turned 30 deg on the
// spot (as a corridor's loosened edges can leave a pass's poses): the second lap ties its places to the first from
// keyframe 36 on, and then meets the turned ones. Each loop there is a true match that says the query must turn
// 30 deg, against a candidate whose own pose is what is wrong.
std::unique_ptr<LoopClosure> twoLapsPastTurnedKeyframes(bool through_loops) {
  LoopClosureConfig c;
  c.min_age = 15.0;  // keyframes are 1 s apart
  c.database.exclude_recent = 10;
  c.database.descriptor.lateral_steps = 0;
  c.skip_after_loop = 0;
  c.submap_keyframes = 0;  // the candidate's own (complete) view: its neighbours' poses do not blur the match
  c.max_rotation_drift_ratio = 0.02;  // [rad/m] a lap of path (25 m) opens the rotation budget to 40 deg
  c.budget_through_loops = through_loops;
  auto loops = std::make_unique<LoopClosure>(c);
  lidar::LocalMap map;
  for (int i = 0; i <= 60; ++i) {
    lidar::FeatureSet f = test::seenFrom(test::courtyard(0), driftLapPose(i));
    f.t = fromSeconds(i);
    const bool turned = i >= 12 && i <= 15;
    const Eigen::Isometry3d T_est = turned ? driftLapPose(i) * test::planarPose(0, 0, 30.0) : driftLapPose(i);
    if (loops->addKeyframe(map, map.addKeyframe(f, T_est), geometry::Matrix6d::Zero())) {
      const std::vector<Eigen::Isometry3d> poses = loops->poses();
      for (std::size_t k = 0; k < poses.size(); ++k) map.updatePose(k, poses[k]);
    }
  }
  return loops;
}

TEST(LoopClosure, APlaceTiedByALoopAMomentAgoIsNotTurnedThirtyDegreesTowardsACandidateWhosePoseIsWrong) {
  const double step = 8 * std::sin(5 * kPi / 180);  // [m] chord between neighbouring keyframes
  const auto guarded = twoLapsPastTurnedKeyframes(true);
  ASSERT_GE(guarded->stats().accepted, 5u) << "the second lap ties its places to the first";
  std::vector<std::pair<std::size_t, std::size_t>> tied;  // accepted so far (candidate, query)
  int refused = 0;
  for (const LoopEvent& e : guarded->events()) {
    const bool turned_candidate = e.candidate >= 12 && e.candidate <= 15;
    // Known answer: the fewest keyframe steps from the query to the candidate, along the chain or through one
    // earlier loop (a step back to its query, the loop, steps on to the candidate).
    std::size_t steps = e.query - e.candidate;
    for (const auto& [c, q] : tied) {
      const std::size_t via = (e.query > q ? e.query - q : q - e.query) +
                              (e.candidate > c ? e.candidate - c : c - e.candidate);
      steps = std::min(steps, via);
    }
    EXPECT_NEAR(e.rotation_budget, 0.2 + 0.02 * step * static_cast<double>(steps), 1e-3)
        << "query " << e.query << ", candidate " << e.candidate;
    if (e.verification.accepted) {
      tied.emplace_back(e.candidate, e.query);
      EXPECT_LT(e.implied_rotation * 180 / kPi, 2.0) << "query " << e.query << ", candidate " << e.candidate;
      EXPECT_FALSE(turned_candidate);
    } else if (turned_candidate && e.query >= 36) {  // the second lap (the first meets only the far side)
      ++refused;
      EXPECT_NE(e.verification.reason.find("rotation budget"), std::string::npos) << e.verification.reason;
      EXPECT_NEAR(e.implied_rotation * 180 / kPi, 30.0, 2.0);
    }
  }
  EXPECT_GE(refused, 3);
  // Along the keyframe chain the budget is the lap of path between them (40 deg), and the 30 deg loops go in.
  const auto chained = twoLapsPastTurnedKeyframes(false);
  int turned_in = 0;
  for (const LoopEvent& e : chained->events()) {
    // (Within 1 %: the 30 deg loops it accepts bend the graph, and the steps' lengths with it.)
    const double chain = 0.2 + 0.02 * step * static_cast<double>(e.query - e.candidate);
    EXPECT_NEAR(e.rotation_budget, chain, 0.01 * chain);
    turned_in += e.verification.accepted && e.implied_rotation * 180 / kPi > 25.0;
  }
  EXPECT_GE(turned_in, 1);
}

}  // namespace
}  // namespace drover::pipeline
