// Loop closure on synthetic courtyards with exact ground truth: a drifting lap is pulled back onto the truth when it
// returns to its start, twin places and turned loops are refused by the budgets, retired keyframes merge, events
// are bounded. The simulated overlap course is test_loop_closure_sim.cpp.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <memory>
#include <numbers>

#include "geometry/so3.hpp"
#include "pipeline/loop_closure.hpp"
#include "support/courtyard.hpp"
#include "support/units.hpp"

namespace drover::pipeline {
namespace {

using ::drover::test::kPi;

LoopClosureConfig courtyardConfig() {
  LoopClosureConfig c;
  c.min_age = 15.0;  // keyframes are 1 s apart below
  c.database.exclude_recent = 10;
  c.database.descriptor.lateral_steps = 0;
  c.skip_after_loop = 0;
  return c;
}

// Keyframe i of a lap of radius 4 m around the courtyard's centre, 10 deg apart, heading along the circle.
Eigen::Isometry3d lapPose(int i) {
  const double theta = i * 10.0 * kPi / 180.0;
  return test::planarPose(4 * std::cos(theta), 4 * std::sin(theta), i * 10.0 + 90.0);
}

TEST(LoopClosure, PullsADriftingLapBackOntoTheTruthWhenItReturnsToItsStart) {
  const lidar::FeatureSet world = test::courtyard(0);
  lidar::LocalMap map;
  LoopClosureConfig config = courtyardConfig();
  // This odometry turns 24 deg too far in 28 m, far more than a lidar-inertial odometry does (the default rotation
  // budget, 11 deg + 2.9 deg per 100 m, would refuse the loop as one that cannot be true): opened for it here.
  config.max_rotation_drift_floor = 0.6;  // [rad]
  LoopClosure loops(config);
  // Odometry with a 0.6 deg yaw error and 4 % scale error per step: after 40 steps the last pose is off by
  // 24 deg and more than a metre.
  Eigen::Isometry3d T_est = lapPose(0);
  double worst_before = 0;
  int closed = 0;
  for (int i = 0; i <= 40; ++i) {
    if (i > 0) {
      Eigen::Isometry3d step = lapPose(i - 1).inverse() * lapPose(i);
      step.translation() *= 1.04;
      T_est = T_est * step * test::planarPose(0, 0, 0.6);
    }
    lidar::FeatureSet f = test::seenFrom(world, lapPose(i));
    f.t = fromSeconds(i);
    const std::size_t index = map.addKeyframe(f, T_est);
    worst_before = std::max(worst_before, (T_est.translation() - lapPose(i).translation()).norm());
    if (loops.addKeyframe(map, index, geometry::Matrix6d::Zero())) {
      ++closed;
      const std::vector<Eigen::Isometry3d> poses = loops.poses();
      for (std::size_t k = 0; k < poses.size(); ++k) map.updatePose(k, poses[k]);
      T_est = poses.back();
    }
  }
  ASSERT_GE(closed, 1);
  for (const LoopEvent& e : loops.events()) {
    if (!e.verification.accepted) continue;
    const Eigen::Isometry3d T_true = lapPose(int(e.candidate)).inverse() * lapPose(int(e.query));
    // The verification submap is voxel-downsampled (0.2 m edges, 0.4 m planes): a decimetre at worst here.
    EXPECT_LT((T_true.inverse() * e.verification.T_candidate_query).translation().norm(), 0.25);
  }
  // Up to the gauge (keyframe 0 fixed at its true pose), the corrected lap is close to the truth.
  const std::vector<Eigen::Isometry3d> poses = loops.poses();
  double worst_after = 0;
  for (std::size_t k = 0; k < poses.size(); ++k)
    worst_after = std::max(worst_after, (poses[k].translation() - lapPose(int(k)).translation()).norm());
  std::printf("lap of 41 keyframes: %d loops, worst position error %.3f m before, %.3f m after\n", closed, worst_before,
              worst_after);
  EXPECT_GT(worst_before, 1.0);
  EXPECT_LT(worst_after, 0.35 * worst_before);
  EXPECT_LT((poses.back().translation() - lapPose(40).translation()).norm(), 0.3);
}

TEST(LoopClosure, ATwinPlaceThirtyMetresAwayFitsPerfectlyButIsRejectedByTheDriftBudget) {
  // Two identical courtyards 30 m apart; the robot does most of a lap in the first, moves to the second and starts
  // the same lap there. Every view of the second is a perfect match for a view of the first.
  const lidar::FeatureSet world = test::courtyard(0);
  const Eigen::Isometry3d twin = test::planarPose(30, 0, 0);
  lidar::LocalMap map;
  LoopClosure loops(courtyardConfig());
  for (int k = 0; k < 40; ++k) {
    const int lap = k < 20 ? k : k - 20;
    lidar::FeatureSet f = test::seenFrom(world, lapPose(lap));
    f.t = fromSeconds(k);
    const Eigen::Isometry3d T_world_lidar = k < 20 ? lapPose(lap) : twin * lapPose(lap);  // exact odometry
    EXPECT_FALSE(loops.addKeyframe(map, map.addKeyframe(f, T_world_lidar), geometry::Matrix6d::Zero()));
  }
  EXPECT_EQ(loops.stats().accepted, 0u);
  ASSERT_GE(loops.stats().over_drift_budget, 1u);  // scan matching alone would have accepted them
  // Besides the twin (30 m), the rectangular courtyard is nearly point-symmetric: a view from the opposite side of
  // the lap, turned by 180 deg, fits as well (8 m, the lap's diameter). Scan matching accepts both.
  int twins = 0;
  for (const LoopEvent& e : loops.events()) {
    EXPECT_FALSE(e.verification.accepted);
    twins += std::abs(e.implied_drift - 30.0) < 0.5 && e.verification.reason.find("drift budget") != std::string::npos;
  }
  EXPECT_GE(twins, 5);
}

// The lap with exact positions but, from keyframe 20 on, every heading 30 deg off (as after a bad turn): the loops
// back to the start are true, with the true relative pose, and say the query must turn 30 deg, while its position
// is right. The default rotation budget (11 deg + 2.9 deg per 100 m of the ~28 m between them) refuses them; a
// looser one accepts them.
std::unique_ptr<LoopClosure> lapWithAHeadingError(const LoopClosureConfig& c,
                                                  const geometry::Matrix6d& degenerate = geometry::Matrix6d::Zero()) {
  auto loops = std::make_unique<LoopClosure>(c);
  lidar::LocalMap map;
  for (int i = 0; i <= 40; ++i) {
    lidar::FeatureSet f = test::seenFrom(test::courtyard(0), lapPose(i));
    f.t = fromSeconds(i);
    const Eigen::Isometry3d T_est = i < 20 ? lapPose(i) : lapPose(i) * test::planarPose(0, 0, 30.0);
    if (loops->addKeyframe(map, map.addKeyframe(f, T_est), degenerate)) {
      const std::vector<Eigen::Isometry3d> poses = loops->poses();
      for (std::size_t k = 0; k < poses.size(); ++k) map.updatePose(k, poses[k]);
    }
  }
  return loops;
}

TEST(LoopClosure, ALoopThatWouldTurnTheQueryBeyondTheRotationBudgetIsRejectedAndALooserBudgetAcceptsIt) {
  const auto strict = lapWithAHeadingError(courtyardConfig());
  EXPECT_EQ(strict->stats().accepted, 0u);
  int turned = 0;
  for (const LoopEvent& e : strict->events()) {
    if (e.verification.reason.find("rotation budget") == std::string::npos) continue;
    ++turned;
    EXPECT_NEAR(e.implied_rotation * 180 / kPi, 30.0, 2.0);
    EXPECT_LT(e.implied_drift, 0.3) << "the position was right";
    EXPECT_NEAR(e.rotation_budget, 0.2 + 0.0005 * 4 * 2 * kPi * (e.query - e.candidate) / 36.0, 0.01);
  }
  EXPECT_GE(turned, 1);
  // Every step degenerate along x (a corridor): the translation budget opens by 0.5 m a step, the rotation budget
  // not at all (a degenerate translation says nothing about the heading), and the loops are still refused.
  geometry::Matrix6d along_x = geometry::Matrix6d::Zero();
  along_x(0, 0) = 1.0;
  LoopClosureConfig searched = courtyardConfig();
  searched.skip_degenerate_places = false;  // the default, said: the budgets are what is tested here
  const auto corridor = lapWithAHeadingError(searched, along_x);
  EXPECT_EQ(corridor->stats().accepted, 0u);
  int in_corridor = 0;
  for (const LoopEvent& e : corridor->events()) {
    if (e.verification.reason.find("rotation budget") == std::string::npos) continue;
    ++in_corridor;
    EXPECT_GT(e.drift_budget, 2.0 + 0.5 * static_cast<double>(e.query - e.candidate) - 0.01);
    EXPECT_NEAR(e.rotation_budget, 0.2 + 0.0005 * 4 * 2 * kPi * (e.query - e.candidate) / 36.0, 0.01);
  }
  EXPECT_GE(in_corridor, 1);
  LoopClosureConfig loose = courtyardConfig();
  loose.max_rotation_drift_floor = 0.7;  // [rad] 40 deg
  const auto accepted = lapWithAHeadingError(loose);
  ASSERT_GE(accepted->stats().accepted, 1u);
  const auto first = std::find_if(accepted->events().begin(), accepted->events().end(),
                                  [](const LoopEvent& e) { return e.verification.accepted; });
  EXPECT_NEAR(first->implied_rotation * 180 / kPi, 30.0, 2.0);
}

// Runs the exact (drift-free) lap with the given config and optional visual prior; returns the loop closure.
std::unique_ptr<LoopClosure> exactLap(const LoopClosureConfig& c, VisualYawPrior prior = {}) {
  auto loops = std::make_unique<LoopClosure>(c);
  loops->setVisualYawPrior(std::move(prior));
  lidar::LocalMap map;
  for (int i = 0; i <= 40; ++i) {
    lidar::FeatureSet f = test::seenFrom(test::courtyard(0), lapPose(i));
    f.t = fromSeconds(i);
    if (loops->addKeyframe(map, map.addKeyframe(f, lapPose(i)), geometry::Matrix6d::Zero())) {
      const std::vector<Eigen::Isometry3d> poses = loops->poses();
      for (std::size_t k = 0; k < poses.size(); ++k) map.updatePose(k, poses[k]);
    }
  }
  return loops;
}

// The lap of exactLap, but the odometry reported a degenerate direction (along x) on its first 5 keyframes: the
// returns to the start find candidates only there, and they are not loops to trust.
TEST(LoopClosure, AskedToSkipDegeneratePlacesItClosesNoLoopWhereTheOdometryWasDegenerate) {
  for (const bool skip : {true, false}) {
    LoopClosureConfig c = courtyardConfig();
    c.skip_degenerate_places = skip;
    LoopClosure loops(c);
    lidar::LocalMap map;
    for (int i = 0; i <= 40; ++i) {
      lidar::FeatureSet f = test::seenFrom(test::courtyard(0), lapPose(i));
      f.t = fromSeconds(i);
      geometry::Matrix6d degenerate = geometry::Matrix6d::Zero();
      if (i >= 1 && i <= 4) degenerate(0, 0) = 1.0;
      if (loops.addKeyframe(map, map.addKeyframe(f, lapPose(i)), degenerate)) {
        const std::vector<Eigen::Isometry3d> poses = loops.poses();
        for (std::size_t k = 0; k < poses.size(); ++k) map.updatePose(k, poses[k]);
      }
    }
    if (skip) {
      EXPECT_EQ(loops.stats().accepted, 0u);
      EXPECT_GE(loops.stats().degenerate_places, 1u);
      for (const LoopEvent& e : loops.events()) EXPECT_GE(e.candidate, 6u) << "2 keyframes clear of the stretch";
    } else {
      EXPECT_GE(loops.stats().accepted, 1u) << "the same lap closes when degenerate places are searched";
      EXPECT_EQ(loops.stats().degenerate_places, 0u);
    }
  }
}

TEST(LoopClosure, TheRadiusSourceFindsTheStartAgainFromTheEstimateAlone) {
  LoopClosureConfig c = courtyardConfig();
  c.source = LoopSource::kRadius;
  c.radius = 3.0;
  const auto loops = exactLap(c);
  ASSERT_GE(loops->stats().accepted, 1u);
  for (const LoopEvent& e : loops->events()) {
    EXPECT_EQ(e.source, "radius");
    EXPECT_LT(e.sc_distance, 0.0);  // no Scan Context involved
    if (e.verification.accepted) {
      EXPECT_LT(e.implied_drift, 0.25);
    }
  }
}

TEST(LoopClosure, AVisualYawPriorIsUsedForTheShiftSearchWhenItHasOne) {
  int asked = 0;
  // The lap's true relative yaw, as a VIS that tracked through both keyframes would give it.
  const auto loops = exactLap(courtyardConfig(), [&](Time t_candidate, Time t_query) -> std::optional<double> {
    ++asked;
    const Eigen::Matrix3d R =
        (lapPose(int(toSeconds(t_candidate))).linear().transpose() * lapPose(int(toSeconds(t_query))).linear());
    return std::atan2(R(1, 0), R(0, 0));
  });
  EXPECT_GT(asked, 0);
  EXPECT_EQ(loops->stats().visual_priors, static_cast<std::size_t>(asked));
  EXPECT_GE(loops->stats().accepted, 1u);
  for (const LoopEvent& e : loops->events())
    if (e.verification.accepted) {
      EXPECT_TRUE(e.narrowed && !e.fell_back);
    }
}

// Two laps of 36 keyframes round the courtyard with 1 cm and 0.1 deg of odometry error a step (the second lap
// starts 0.36 m and 3.6 deg off the first); the loops found are applied as the LIS does.
std::unique_ptr<LoopClosure> twoLaps(const LoopClosureConfig& c) {
  auto loops = std::make_unique<LoopClosure>(c);
  lidar::LocalMap map;
  for (int i = 0; i < 72; ++i) {
    lidar::FeatureSet f = test::seenFrom(test::courtyard(0), lapPose(i));
    f.t = fromSeconds(i);
    if (loops->addKeyframe(map, map.addKeyframe(f, lapPose(i) * test::planarPose(0.01 * i, 0, 0.1 * i)),
                           geometry::Matrix6d::Zero())) {
      const std::vector<Eigen::Isometry3d> poses = loops->poses();
      for (std::size_t k = 0; k < poses.size(); ++k) map.updatePose(k, poses[k]);
    }
  }
  return loops;
}

// A long run keeps only its newest verified candidates in memory (config.max_events); the loops it closes and the
// poses are the same, and the counts still cover every one.
TEST(LoopClosure, KeepsOnlyTheNewestEventsPastMaxEventsAndClosesTheSameLoops) {
  LoopClosureConfig all = courtyardConfig();
  all.max_events = 0;
  const std::unique_ptr<LoopClosure> every = twoLaps(all);
  const std::vector<LoopEvent>& full = every->events();
  ASSERT_GE(full.size(), 10u);
  EXPECT_EQ(every->eventsDropped(), 0u);
  LoopClosureConfig bounded = courtyardConfig();
  bounded.max_events = 4;
  const std::unique_ptr<LoopClosure> newest = twoLaps(bounded);
  const std::vector<LoopEvent>& kept = newest->events();
  EXPECT_LE(kept.size(), 4u);
  EXPECT_GE(kept.size(), 2u);
  EXPECT_EQ(newest->eventsDropped() + kept.size(), full.size());
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const LoopEvent& twin = full[newest->eventsDropped() + i];
    EXPECT_EQ(kept[i].query, twin.query);
    EXPECT_EQ(kept[i].candidate, twin.candidate);
  }
  EXPECT_EQ(newest->stats().verified, every->stats().verified);
  EXPECT_EQ(newest->stats().accepted, every->stats().accepted);
  const std::vector<Eigen::Isometry3d> a = every->poses(), b = newest->poses();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_LT((a[i].translation() - b[i].translation()).norm(), 1e-12);
  bounded.max_events = -1;
  EXPECT_NE(bounded.validate().find("max_events"), std::string::npos);
}

// The second lap retires the first's keyframes, each by its twin a lap later. Where loops tied the laps together
// the retired nodes merge and poses() still gives every keyframe where it was; with no loop (search disabled) or
// with keep_retired_nodes, the graph keeps them all.
TEST(LoopClosure, ARetiredKeyframesGraphNodeIsMergedWhereALoopTiedItsPlaceToTheNewerOne) {
  for (const int mode : {0, 1, 2}) {  // merge, keep_retired_nodes, no loops
    LoopClosureConfig c = courtyardConfig();
    c.keep_retired_nodes = mode == 1;
    c.enabled = mode != 2;
    const std::unique_ptr<LoopClosure> loops = twoLaps(c);
    if (mode != 2) {
      ASSERT_GE(loops->stats().accepted, 10u);
    }
    const std::vector<Eigen::Isometry3d> before = loops->poses();
    for (std::size_t i = 0; i < 36; ++i) loops->retire(i, i + 36);
    EXPECT_EQ(loops->stats().retired, 36u);
    const std::size_t merged = loops->stats().merged;
    if (mode == 0) {
      EXPECT_GE(merged, 30u) << "loops everywhere on the second lap: nearly every place is tied";
    } else {
      EXPECT_EQ(merged, 0u);
    }
    EXPECT_EQ(merged + loops->stats().unmerged, mode == 1 ? 0u : 36u);
    EXPECT_EQ(loops->graphNodes(), 72u - merged);
    const std::vector<Eigen::Isometry3d> after = loops->poses();
    ASSERT_EQ(after.size(), 72u);
    for (std::size_t i = 0; i < 72; ++i) {
      EXPECT_LT((after[i].translation() - before[i].translation()).norm(), 1e-9) << i;
      EXPECT_LT(geometry::logSO3(after[i].linear().transpose() * before[i].linear()).norm(), 1e-9) << i;
    }
  }
  LoopClosure loops{courtyardConfig()};
  EXPECT_THROW(loops.retire(0, 0), std::invalid_argument);
}

TEST(LoopClosure, DisabledItStillKeepsTheGraphButNeverSearches) {
  LoopClosureConfig c = courtyardConfig();
  c.enabled = false;
  LoopClosure loops(c);
  lidar::LocalMap map;
  for (int i = 0; i <= 40; ++i) {
    lidar::FeatureSet f = test::seenFrom(test::courtyard(0), lapPose(i));
    f.t = fromSeconds(i);
    EXPECT_FALSE(loops.addKeyframe(map, map.addKeyframe(f, lapPose(i)), geometry::Matrix6d::Zero()));
  }
  EXPECT_EQ(loops.stats().queries, 0u);
  EXPECT_EQ(loops.poses().size(), 41u);
}

TEST(LoopClosure, RejectsInvalidConfigsAndOutOfOrderKeyframes) {
  LoopClosureConfig c;
  c.max_verifications = 0;
  EXPECT_THROW(LoopClosure{c}, std::invalid_argument);
  c = {};
  c.radius = -1;
  EXPECT_THROW(LoopClosure{c}, std::invalid_argument);
  c = {};
  c.max_rotation_drift_ratio = -0.001;
  EXPECT_NE(c.validate().find("max_rotation_drift_ratio"), std::string::npos);
  c = {};
  c.max_rotation_drift_floor = 0;
  EXPECT_NE(c.validate().find("max_rotation_drift_floor"), std::string::npos);
  LoopClosure loops{LoopClosureConfig{}};
  EXPECT_THROW(loops.retire(0, 1), std::invalid_argument);
  lidar::LocalMap map;
  map.addKeyframe(test::courtyard(0), Eigen::Isometry3d::Identity());
  map.addKeyframe(test::courtyard(0), Eigen::Isometry3d::Identity());
  EXPECT_THROW(loops.addKeyframe(map, 1, geometry::Matrix6d::Zero()), std::invalid_argument);
}

}  // namespace
}  // namespace drover::pipeline
