// Loop closure in the LIS on the simulated "overlap" course (driven twice around the same loop): every accepted loop
// is a true one, with the true relative pose, the trajectory stays accurate, and the second pass retires the first
// pass's keyframes where it drives them again.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "eval/ape.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "pipeline/loop_closure.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"
#include "support/units.hpp"

namespace drover::pipeline {
namespace {

using ::drover::test::kPi;

// The simulated overlap course: 88 s, 82 m, a loop driven and then partly driven again.
struct OverlapRun {
  Trajectory lidar_truth;  // T_world_lidar at every sweep
  double ape = 0;          // [m] rmse, SE(3)-aligned
  std::vector<LoopEvent> events;
  LoopStats stats;
  OdometryStats odometry;
  std::size_t graph_nodes = 0;
  std::vector<lidar::Keyframe> keyframes;  // as they ended (poses corrected, the retired ones marked)
};

double apeRmse(const Trajectory& truth, const Trajectory& est) {
  eval::ApeOptions o;
  o.alignment = eval::Alignment::kSe3;
  return eval::computeApe(truth, est, o).stats.rmse;
}

const OverlapRun& overlap() {
  static const OverlapRun run = [] {
    const sim::Scenario scenario = sim::makeScenario("overlap", sim::ScenarioOptions{});
    sim::SimulatorConfig sc = sim::SimulatorConfig::defaults();
    sc.enable_camera = false;
    const sim::Simulator simulator(scenario, sc, 3);
    std::vector<Measurement> stream;
    simulator.run([&](Measurement&& m) { stream.push_back(std::move(m)); });
    OdometryConfig config;
    config.layout.min_range = config.features.min_range = 0.8;
    config.features.surf_leaf = 0.2f;
    config.local_map.plane_leaf = 0.2;
    config.local_map.retire_age = 20.0;  // [s] the second pass ends 28 s after it begins
    OverlapRun out;
    const Eigen::Isometry3d T_imu_lidar = simulator.calibration().T_imu_lidar;
    for (const StampedPose& p : simulator.groundTruth()) out.lidar_truth.push_back({p.t, p.T_world_body * T_imu_lidar});
    LidarOdometry odometry(config, simulator.calibration());
    for (const Measurement& m : stream) odometry.process(m);
    odometry.finish();
    out.ape = apeRmse(out.lidar_truth, odometry.trajectory());
    out.events = odometry.loopClosure().events();
    out.stats = odometry.loopClosure().stats();
    out.odometry = odometry.stats();
    out.graph_nodes = odometry.loopClosure().graphNodes();
    for (std::size_t i = 0; i < odometry.keyframeMap().size(); ++i) out.keyframes.push_back(odometry.keyframeMap().keyframe(i));
    return out;
  }();
  return run;
}

Eigen::Isometry3d truthPoseAt(const Trajectory& truth, Time t) {
  for (const StampedPose& p : truth)
    if (std::abs(p.t - t) < 3'000'000) return p.T_world_body;
  ADD_FAILURE() << "no ground truth at " << t;
  return Eigen::Isometry3d::Identity();
}

TEST(LoopClosureSim, EveryAcceptedLoopOnTheOverlapCourseIsTrueAndTheTrajectoryStaysWithinFiveCentimetres) {
  const OverlapRun& r = overlap();
  std::printf("overlap: %zu queries, %zu verified, %zu accepted; APE rmse %.4f m\n", r.stats.queries, r.stats.verified,
              r.stats.accepted, r.ape);
  EXPECT_GE(r.stats.accepted, 3u);
  for (const LoopEvent& e : r.events) {
    if (!e.verification.accepted) continue;
    const Eigen::Isometry3d T_true =
        truthPoseAt(r.lidar_truth, e.t_candidate).inverse() * truthPoseAt(r.lidar_truth, e.t_query);
    const Eigen::Isometry3d err = T_true.inverse() * e.verification.T_candidate_query;
    EXPECT_LT(err.translation().norm(), 0.3) << "loop " << e.query << " -> " << e.candidate;
    EXPECT_LT(Eigen::AngleAxisd(err.linear()).angle() * 180 / kPi, 1.0);
    EXPECT_LT(T_true.translation().norm(), 5.0);
  }
  // Without loops this course gives 0.016 m (the lidar-inertial odometry alone is good here); the loops must not
  // spoil it. (One test: ctest runs each test in its own process, and the course takes ~15 s.)
  EXPECT_LT(r.ape, 0.05);
  // The second pass supersedes the first where it drives it again (LocalMapConfig::retire_radius, 2 m, here 20 s):
  // each retired keyframe has a keyframe at least 20 s newer within 2 m (its corrected pose: 2.1 m). Only the
  // keyframes of the second pass's first 8 s become 20 s old before the course ends.
  std::printf("overlap: %zu keyframes, %zu retired\n", r.keyframes.size(), r.odometry.keyframes_retired);
  EXPECT_GE(r.odometry.keyframes_retired, 3u);
  std::size_t retired = 0;
  for (const lidar::Keyframe& old : r.keyframes) {
    if (!old.retired) continue;
    ++retired;
    EXPECT_TRUE(old.features().full.empty());
    const bool superseded = std::any_of(r.keyframes.begin(), r.keyframes.end(), [&](const lidar::Keyframe& k) {
      return k.t >= old.t + fromSeconds(20.0) &&
             (k.T_world_lidar.translation() - old.T_world_lidar.translation()).norm() <
                 lidar::LocalMapConfig{}.retire_radius + 0.1;
    });
    EXPECT_TRUE(superseded) << "keyframe " << old.index;
  }
  EXPECT_EQ(retired, r.odometry.keyframes_retired);
  // Their graph nodes were merged into the keyframes that stand for them where a loop tied the passes together.
  std::printf("overlap: %zu graph nodes, %zu merged, %zu kept\n", r.graph_nodes, r.stats.merged, r.stats.unmerged);
  EXPECT_EQ(r.stats.merged + r.stats.unmerged, retired);
  EXPECT_GE(r.stats.merged, 1u);
  EXPECT_EQ(r.graph_nodes, r.keyframes.size() - r.stats.merged);
}

}  // namespace
}  // namespace drover::pipeline
