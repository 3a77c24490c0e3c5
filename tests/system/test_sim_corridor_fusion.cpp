// The VIS carries the LIS through the lidar-degenerate corridor (44.5 s, 38 m with nothing along its axis within
// lidar range): its motion between sweeps, a relative-pose factor in the LIS's IMU smoother, holds the axis the
// scan matcher leaves to the IMU. The LIS alone drifts 7.0 % here (test_sim_corridor_drift.cpp); fused, 0.36 %.
// Driven as `drover run` drives it: one time-ordered stream, the VIS started from the LIS and fed its sweeps.
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <string>

#include "support/fused_run.hpp"

namespace drover {
namespace {

using test::FusedRun;
using test::runFused;

// Tests that stop early simulate only the seconds they use (plus one): the camera's rendering is half of a whole
// corridor test's time, and the course's first seconds come out the same when it is cut (the spline and every
// sensor's noise are functions of time).
FusedRun runFusedOnTheCorridor(std::vector<sim::SensorFault> faults = {}) {
  return runFused(test::simulateLiveCourse("corridor", 0, 1, true, std::move(faults)));
}

TEST(SimCorridorFusion, TheVisMotionFactorCarriesTheLisThroughTheDegenerateCorridorWithinOnePercent) {
  const FusedRun r = runFusedOnTheCorridor();
  std::printf("corridor with the VIS fused: %.1f m, end error %.3f m (%.2f %%); %zu of %zu sweeps degenerate, "
              "%zu with the VIS factor, %zu with its guess; %zu VIS frames; %zu smoother resets\n",
              r.path, r.end_error, 100 * r.end_error / r.path, r.stats.degenerate_scans, r.stats.scans_processed,
              r.stats.vis_factor_scans, r.stats.vis_guess_scans, r.vis_frames, r.stats.smoother_resets);
  ASSERT_GT(r.path, 30.0);
  EXPECT_EQ(r.stats.smoother_resets, 0u);
  EXPECT_GT(r.stats.degenerate_scans, r.stats.scans_processed * 9 / 10) << "the corridor must stay degenerate";
  EXPECT_GT(r.stats.vis_factor_scans, r.stats.scans_processed * 8 / 10);
  // measured 0.36 % (LIS alone 7.0 %; 0.46 % with the keyframe gate on time alone)
  EXPECT_LT(r.end_error / r.path, 0.01);
}

// Without the factor the VIS's motion reaches the LIS only as the matcher's guess. A degenerate match keeps its
// degenerate directions at that guess, so its pose is then the sweep's (as LIO-SAM's); taking the smoother's, which
// saw the VIS only through the match's loosened directions, drifted 38.9 % here, and the VIS with it (it takes its
// depths from the LIS).
TEST(SimCorridorFusion, TheVisMotionAsTheMatchersGuessAloneCarriesTheCorridorWithinOnePercent) {
  const FusedRun r = runFused(test::simulateLiveCourse("corridor", 0, 1, true), 0, false);
  std::printf("corridor, the VIS as the guess only: %.1f m, end error %.3f m (%.2f %%); %zu of %zu sweeps with its "
              "guess; %zu VIS resets by the LIS\n",
              r.path, r.end_error, 100 * r.end_error / r.path, r.stats.vis_guess_scans, r.stats.scans_processed,
              r.resets_by_the_lis);
  ASSERT_GT(r.path, 30.0);
  EXPECT_EQ(r.stats.vis_factor_scans, 0u);
  EXPECT_GT(r.stats.vis_guess_scans, r.stats.scans_processed * 8 / 10);
  EXPECT_LT(r.end_error / r.path, 0.01);
}

// Where the lidar constrains all six directions the matcher starts from the IMU's prediction, the VIS's motion being
// the guess only after a degenerate sweep (vis_fusion.initial_guess_degenerate_only; on kitti05-replay the VIS's
// guess on every sweep cost 0.156 -> 0.160 m). sharp-turns never degenerates the lidar; LVI-SAM's rule (false)
// takes the VIS's guess on every sweep once the VIS is healthy.
TEST(SimCorridorFusion, WhereTheLidarHoldsEveryDirectionTheMatcherStartsFromTheImuNotTheVis) {
  const test::LiveCourse course = test::simulateLiveCourse("sharp-turns", 8, 1, true);
  const auto every_sweep = [](pipeline::OdometryConfig& c) { c.vis_fusion.initial_guess_degenerate_only = false; };
  const FusedRun lvi_sam = runFused(course, 0, true, every_sweep);
  const FusedRun drover = runFused(course, 0, true);
  std::printf("sharp-turns 8 s: %zu sweeps, %zu degenerate; the VIS's guess on %zu (every sweep) / %zu (after a "
              "degenerate sweep)\n",
              drover.stats.scans_processed, drover.stats.degenerate_scans, lvi_sam.stats.vis_guess_scans,
              drover.stats.vis_guess_scans);
  ASSERT_EQ(drover.stats.degenerate_scans, 0u) << "the course must hold the lidar in every direction";
  EXPECT_GT(lvi_sam.stats.vis_guess_scans, 30u) << "the VIS must be healthy for this to test anything";
  EXPECT_EQ(drover.stats.vis_guess_scans, 0u);
}

// Either side survives the other's failure: the camera covered for 5 s (then overexposed while its auto exposure
// settles), the lidar silent for 3 s and the IMU for 0.5 s, all inside the corridor where the lidar alone cannot
// hold the axis. The VIS resets and re-initialises from the LIS; the LIS carries on with the IMU and the VIS.
TEST(SimCorridorFusion, ACameraBlackoutALidarDropoutAndAnImuGapInTheCorridorAreSurvivedWithinOnePercent) {
  constexpr Time kS = 1'000'000'000;
  const FusedRun r = runFusedOnTheCorridor({{sim::FaultKind::kCameraBlackout, 5 * kS, 10 * kS},
                                            {sim::FaultKind::kLidarDropout, 13 * kS, 16 * kS},
                                            {sim::FaultKind::kImuGap, 18 * kS, 18 * kS + kS / 2}});
  std::printf("corridor with faults: %.1f m, end error %.3f m (%.2f %%); %zu sweeps, %zu with the VIS factor; %zu VIS "
              "resets of its own, %zu by the LIS; %zu smoother resets\n",
              r.path, r.end_error, 100 * r.end_error / r.path, r.stats.scans_processed, r.stats.vis_factor_scans,
              r.vis_resets, r.resets_by_the_lis, r.stats.smoother_resets);
  ASSERT_GT(r.path, 30.0);
  EXPECT_LT(r.stats.scans_processed, 420u) << "the dropout's 30 sweeps are missing";
  EXPECT_GE(r.vis_resets, 2u) << "the blackout and the IMU gap each clear the VIS's window";
  EXPECT_GT(r.stats.vis_factor_scans, r.stats.scans_processed * 6 / 10) << "the VIS re-joined";
  EXPECT_LT(r.end_error / r.path, 0.01);
}

// All four at once, the textureless stretch (21-26 s) last: the VIS's window fills there with KLT tracks that slide
// along edges, and a LIS seed moved by its poses reprojects them pixels off. Seeded anyway (before the seed check),
// the VIS came out with a velocity error the degenerate LIS followed: 46 m lost (122 %). Refused, the window waits
// for texture and a seed that agrees with it (vio/seed_agreement.hpp); the IMU carries the LIS meanwhile.
TEST(SimCorridorFusion, AllFourFaultsIncludingATexturelessStretchAreSurvivedWithinThreePercent) {
  constexpr Time kS = 1'000'000'000;
  const FusedRun r = runFusedOnTheCorridor({{sim::FaultKind::kCameraBlackout, 5 * kS, 10 * kS},
                                            {sim::FaultKind::kLidarDropout, 13 * kS, 16 * kS},
                                            {sim::FaultKind::kImuGap, 18 * kS, 18 * kS + kS / 2},
                                            {sim::FaultKind::kTextureless, 21 * kS, 26 * kS}});
  std::printf("corridor with all four faults: %.1f m, end error %.3f m (%.2f %%); %zu with the VIS factor; %zu VIS "
              "resets of its own, %zu by the LIS\n",
              r.path, r.end_error, 100 * r.end_error / r.path, r.stats.vis_factor_scans, r.vis_resets,
              r.resets_by_the_lis);
  ASSERT_GT(r.path, 30.0);
  EXPECT_GT(r.stats.vis_factor_scans, r.stats.scans_processed / 2) << "the VIS re-joined";
  EXPECT_LT(r.end_error / r.path, 0.03);
}

// A degenerate sweep whose motion the VIS carried loosens the loop graph's odometry edge along its degenerate
// directions by loop.vis_carried_sigma (the VIS drifts along the corridor too, less than the IMU alone; a loop's
// correction belongs where the drift was) or, at 0, leaves it as tight as the lidar's. Seen through the loop search:
// with skip_degenerate_places it skips the keyframes whose edges carry degenerate directions.
TEST(SimCorridorFusion, TheSweepsTheVisCarriedLoosenTheLoopGraphsOdometryEdgesByTheVisSigma) {
  constexpr Time kS = 1'000'000'000;
  const test::LiveCourse course = test::simulateLiveCourse("corridor", 13, 1, true);
  const Time until = course.truth.front().t + 12 * kS;
  const auto sigma = [](double s) {
    return [s](pipeline::OdometryConfig& c) {
      c.loop.skip_degenerate_places = true;
      c.loop.vis_carried_sigma = s;  // [m or rad per sweep]
    };
  };
  EXPECT_GT(pipeline::LoopClosureConfig{}.vis_carried_sigma, 0.0) << "loosened by default";
  const FusedRun loose = runFused(course, until, true, sigma(0.05));
  const FusedRun tight = runFused(course, until, true, sigma(0.0));
  ASSERT_GT(loose.stats.vis_factor_scans, 50u) << "the VIS must be fused for this to test anything";
  std::printf("degenerate places: %zu loosened, %zu held tight (%zu sweeps with the VO factor)\n",
              loose.degenerate_places, tight.degenerate_places, loose.stats.vis_factor_scans);
  EXPECT_GE(loose.degenerate_places, tight.degenerate_places + 5);
}

// The corridor starts standing for 2 s with the lidar degenerate along the axis from the first sweep; the
// accelerometer bias along it (0.02 m/s^2) cannot be seen at rest, so the LIS creeps by 1/2 b t^2 (8 cm by 2.8 s)
// until the VIS's motion arrives (2.9 s). With the static start's velocity known (static_start_sigma_velocity)
// the VO factor then takes the creep out; with the loose 1 m/s prior the smoother explains part of it as a velocity
// error since the start and moves the pose back past the truth (-12 cm at 4 s when the VIS arrived at 3.2 s, before
// the keyframe gate knew the distance moved; -6.6 cm now).
TEST(SimCorridorFusion, AStaticStartsVelocityKnownAtRestLetsTheVisTakeOutTheLisCreepWithoutOvershooting) {
  constexpr Time kS = 1'000'000'000;
  const test::LiveCourse course = test::simulateLiveCourse("corridor", 7, 1, true);
  const Time t0 = course.truth.front().t;
  const FusedRun known = runFused(course, t0 + 6 * kS, true,
                                  [](pipeline::OdometryConfig& c) { c.static_start_sigma_velocity = 0.01; });
  const FusedRun loose = runFused(course, t0 + 6 * kS, true);
  ASSERT_GT(known.stats.vis_factor_scans, 20u) << "the VIS must be fused for this to test anything";
  const double creep = test::sweepErrorAt(known.lis, course, t0 + 2800 * kS / 1000);
  const double known_at_6 = test::sweepErrorAt(known.lis, course, t0 + 6 * kS);
  const double loose_at_6 = test::sweepErrorAt(loose.lis, course, t0 + 6 * kS);
  std::printf("corridor start: LIS error at 2.8 s %.3f m (creep), at 6 s %.3f m with the static velocity known, "
              "%.3f m with the loose prior\n",
              creep, known_at_6, loose_at_6);
  EXPECT_GT(creep, 0.04) << "the creep this test is about";
  // measured 0.035 m, loose 0.062 m (0.033 / 0.110 m with the VIS from 3.2 s)
  EXPECT_LT(known_at_6, 0.05);
  EXPECT_GT(loose_at_6, known_at_6 + 0.02) << "the known velocity is what holds it";
}

// Holding the static start at rest (odometry.static_hold) until the IMU says the robot moved takes the creep out at
// its source: between states of zero motion the IMU factor's velocity change is the accelerometer bias. The hold
// must end at the pull-away (2.0 s), within the sweep where it begins.
TEST(SimCorridorFusion, AStaticStartHeldAtRestDoesNotCreepAndIsReleasedAtThePullAway) {
  constexpr Time kS = 1'000'000'000;
  const test::LiveCourse course = test::simulateLiveCourse("corridor", 7, 1, true);
  const Time t0 = course.truth.front().t;
  const FusedRun held = runFused(course, t0 + 6 * kS, true, [](pipeline::OdometryConfig& c) {
    c.static_hold.sigma = 0.001;
  });
  const FusedRun free = runFused(course, t0 + 6 * kS, true);
  const double held_at_2 = test::sweepErrorAt(held.lis, course, t0 + 2 * kS);
  const double free_at_2 = test::sweepErrorAt(free.lis, course, t0 + 2 * kS);
  const double held_at_6 = test::sweepErrorAt(held.lis, course, t0 + 6 * kS);
  const double free_at_6 = test::sweepErrorAt(free.lis, course, t0 + 6 * kS);
  std::printf("corridor start: LIS error at 2.0 s %.3f m held, %.3f m free; at 6 s %.3f / %.3f m; %s\n", held_at_2,
              free_at_2, held_at_6, free_at_6, held.stats.imu_init.c_str());
  EXPECT_GT(free_at_2, 0.03) << "the creep this test is about";
  // measured 0.001 m held, 0.041 m free; at 6 s 0.032 / 0.062 m
  EXPECT_LT(held_at_2, 0.01);
  EXPECT_LT(held_at_6, free_at_6 - 0.015);
  const std::size_t at = held.stats.imu_init.find("held at rest until ");
  ASSERT_NE(at, std::string::npos) << held.stats.imu_init;
  const double until = std::stod(held.stats.imu_init.substr(at + 19));
  EXPECT_GT(until, 1.95);
  EXPECT_LT(until, 2.15);
}

// The corridor's robot stands 2 s, then pulls away at 0.4 m/s^2; the VIS initialised standing (1.74 s), and its
// first moving keyframe came 0.16 m on, 1.3 s after the standing one. By the keyframe gap's time alone the LIS
// refused it as stalled until the keyframe after that; with the distance the LIS moved over the gap, it takes the
// VIS from its warm-up on.
TEST(SimCorridorFusion, AVisWhoseLastKeyframeWasTakenStandingIsNotRefusedAsStalledAtThePullAway) {
  constexpr Time kS = 1'000'000'000;
  const test::LiveCourse course = test::simulateLiveCourse("corridor", 7, 1, true);
  const Time t0 = course.truth.front().t;
  const auto min_distance = [](double d) {
    return [d](pipeline::OdometryConfig& c) {
      c.vis_fusion.keyframe_gap_min_distance = d;
      c.vis_fusion.keyframe_gap_velocity_tolerance = 0;  // the travel alone: this VIS holds the predicted speed
    };
  };
  const FusedRun by_distance = runFused(course, t0 + 6 * kS, true, min_distance(0.25));
  const FusedRun by_time = runFused(course, t0 + 6 * kS, true, min_distance(0.0));
  ASSERT_GT(by_time.first_vis_factor, 0) << "the VIS must be fused for this to test anything";
  ASSERT_GT(by_distance.first_vis_factor, 0);
  const double first_by_distance = toSeconds(by_distance.first_vis_factor - t0);
  const double first_by_time = toSeconds(by_time.first_vis_factor - t0);
  std::printf("corridor start: the VIS first fused at %.1f s by distance (%zu keyframe-gap refusals), %.1f s by time "
              "alone (%zu)\n",
              first_by_distance, by_distance.keyframe_gap_refusals, first_by_time, by_time.keyframe_gap_refusals);
  EXPECT_GT(by_time.keyframe_gap_refusals, 0u) << "the misfire this test is about";
  EXPECT_EQ(by_distance.keyframe_gap_refusals, 0u);
  EXPECT_LT(first_by_distance, first_by_time - 0.15);
}

// The replay is a function of its input. The LIS's worker threads make the heap's layout differ from run to run, so
// anything that follows addresses (a set of parameter blocks iterated in pointer order) shows up here as the two
// runs parting in the last bits, and then further (the corridor's end error varied 0.17-0.23 m before).
TEST(SimCorridorFusion, TheFusedReplayGivesBitIdenticalPosesWhenRunTwice) {
  constexpr Time kS = 1'000'000'000;
  const test::LiveCourse course = test::simulateLiveCourse("corridor", 13, 1, true);
  const Time until = course.truth.front().t + 12 * kS;
  const FusedRun a = runFused(course, until);
  const FusedRun b = runFused(course, until);
  ASSERT_GT(a.stats.vis_factor_scans, 50u) << "the VIS must be fused for this to test anything";
  ASSERT_EQ(a.lis.size(), b.lis.size());
  for (std::size_t i = 0; i < a.lis.size(); ++i) {
    ASSERT_EQ(a.lis[i].t, b.lis[i].t);
    ASSERT_TRUE(a.lis[i].T_world_body.matrix() == b.lis[i].T_world_body.matrix())
        << "pose " << i << " at " << toSeconds(a.lis[i].t) << " s differs by "
        << (a.lis[i].T_world_body.translation() - b.lis[i].T_world_body.translation()).norm() << " m";
  }
}

}  // namespace
}  // namespace drover
